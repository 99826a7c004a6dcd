#include "csgrt/render/exr.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "csgrt/render/png.h"

namespace csgrt {

namespace {

/// A path beside `target` that no other writer uses, removed on destruction unless `commit`
/// has renamed it over the target. Renaming within a directory is atomic on POSIX, so the
/// target is never seen half-written.
class TemporaryFile {
public:
    explicit TemporaryFile(const std::filesystem::path& target) : target_(target) {
        static std::atomic<unsigned> counter{0};
        // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
        std::string name = ".";
        name.append(target.filename().string()).append(".tmp-");
        name.append(std::to_string(::getpid())).append("-").append(std::to_string(counter++));
        path_ = target.parent_path() / name;
    }
    ~TemporaryFile() {
        std::error_code ignored;
        if (!committed_) std::filesystem::remove(path_, ignored);
    }
    TemporaryFile(const TemporaryFile&) = delete;
    TemporaryFile& operator=(const TemporaryFile&) = delete;

    const std::filesystem::path& path() const { return path_; }

    void commit() {
        std::error_code error;
        std::filesystem::rename(path_, target_, error);
        if (error) {
            throw std::runtime_error("cannot write '" + target_.string() + "': " + error.message());
        }
        committed_ = true;
    }

private:
    std::filesystem::path target_;
    std::filesystem::path path_;
    bool committed_ = false;
};

struct ChannelSpec {
    const char* name;
    Imf::PixelType file_type;
    Imf::PixelType memory_type;
    std::size_t offset;
    double fill;
};

// The channels in file order, with where each lives in a Pixel and what a missing one reads as;
// the half channels come first, in the order of the write buffer.
const std::array<ChannelSpec, 10> kChannels = {{
    {"R", Imf::HALF, Imf::FLOAT, offsetof(Pixel, red), 0.0},
    {"G", Imf::HALF, Imf::FLOAT, offsetof(Pixel, green), 0.0},
    {"B", Imf::HALF, Imf::FLOAT, offsetof(Pixel, blue), 0.0},
    {"A", Imf::HALF, Imf::FLOAT, offsetof(Pixel, alpha), 0.0},
    {"Z", Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, depth), kInfinity},
    {"N.X", Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, normal_x), 0.0},
    {"N.Y", Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, normal_y), 0.0},
    {"N.Z", Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, normal_z), 0.0},
    {"id", Imf::UINT, Imf::UINT, offsetof(Pixel, object_id), double(kNoIndex)},
    {"cost", Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, cost), 0.0},
}};

Imath::V3d to_imath(const Vector3& v) {
    return Imath::V3d(v.x(), v.y(), v.z());
}
Vector3 from_imath(const Imath::V3d& v) {
    return Vector3(v.x, v.y, v.z);
}

/// OpenEXR's world-to-camera matrix: camera at the origin, x right, y up, z along the view
/// (left-handed, as RenderMan), for row vectors (p' = p M) as Imath stores matrices.
Imath::M44f world_to_camera(const Camera& camera) {
    const Vector3 forward = (camera.look_at - camera.position).normalized();
    const Vector3 right = forward.cross(camera.up).normalized();
    const Vector3 up = right.cross(forward);
    const std::array<Vector3, 3> axes = {right, up, forward};
    Imath::M44f matrix;  // identity
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) matrix[i][j] = static_cast<float>(axes[j][i]);
        matrix[3][j] = static_cast<float>(-axes[j].dot(camera.position));
    }
    return matrix;
}

void write_exr_file(const std::filesystem::path& path, const Image& image,
                    const ExrMetadata& metadata) {
    Imf::Header header(image.width(), image.height());
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const ChannelSpec& channel : kChannels) {
        header.channels().insert(channel.name, Imf::Channel(channel.file_type));
    }
    header.insert("resolution", Imf::V2iAttribute(Imath::V2i(image.width(), image.height())));
    const Camera& camera = metadata.camera;
    const bool pinhole = camera.projection == Camera::Projection::Pinhole;
    header.insert("cameraProjection", Imf::StringAttribute(pinhole ? "pinhole" : "orthographic"));
    header.insert("cameraPosition", Imf::V3dAttribute(to_imath(camera.position)));
    header.insert("cameraLookAt", Imf::V3dAttribute(to_imath(camera.look_at)));
    header.insert("cameraUp", Imf::V3dAttribute(to_imath(camera.up)));
    if (pinhole) {
        header.insert("cameraVerticalFov", Imf::DoubleAttribute(camera.vertical_fov_degrees));
    } else {
        header.insert("cameraOrthographicHeight", Imf::DoubleAttribute(camera.orthographic_height));
    }
    Imf::addWorldToCamera(header, world_to_camera(camera));
    header.insert("accelerator", Imf::StringAttribute(metadata.accelerator));
    header.insert("acceleratorBuildMs",
                  Imf::DoubleAttribute(metadata.accelerator_build_milliseconds));
    header.insert("samplesPerPixel", Imf::IntAttribute(metadata.samples_per_pixel));
    header.insert("scene", Imf::StringAttribute(metadata.scene));

    // OpenEXR converts pixel types when reading but not when writing: the colour channels go
    // through a half buffer (R, G, B, A interleaved).
    std::vector<std::array<half, 4>> colour(image.pixel_count());
    for (std::size_t i = 0; i < colour.size(); ++i) {
        const Pixel& pixel = image.pixels()[i];
        colour[i] = {half(pixel.red), half(pixel.green), half(pixel.blue), half(pixel.alpha)};
    }
    Imf::FrameBuffer frame_buffer;
    const char* base = reinterpret_cast<const char*>(image.pixels().data());
    const std::size_t row = sizeof(Pixel) * static_cast<std::size_t>(image.width());
    const std::size_t colour_row = sizeof(colour[0]) * static_cast<std::size_t>(image.width());
    for (std::size_t c = 0; c < kChannels.size(); ++c) {
        const ChannelSpec& channel = kChannels[c];
        if (channel.file_type == Imf::HALF) {
            char* channel_base = reinterpret_cast<char*>(colour.data()) + c * sizeof(half);
            frame_buffer.insert(channel.name,
                                Imf::Slice(Imf::HALF, channel_base, sizeof(colour[0]), colour_row));
        } else {
            frame_buffer.insert(channel.name, Imf::Slice(channel.file_type,
                                                         const_cast<char*>(base + channel.offset),
                                                         sizeof(Pixel), row));
        }
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame_buffer);
    file.writePixels(image.height());
}

template <class Attribute, class Value>
void read_attribute(const Imf::Header& header, const char* name, Value& value) {
    if (const auto* attribute = header.findTypedAttribute<Attribute>(name)) {
        value = attribute->value();
    }
}

}  // namespace

void write_exr(const std::filesystem::path& path, const Image& image, const ExrMetadata& metadata) {
    TemporaryFile temporary(path);
    try {
        write_exr_file(temporary.path(), image, metadata);
    } catch (const std::exception& error) {
        throw std::runtime_error("cannot write '" + path.string() + "': " + error.what());
    }
    temporary.commit();
}

ExrFile read_exr(const std::filesystem::path& path) {
    try {
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        const Imath::Box2i window = header.dataWindow();
        ExrFile result{Image(window.max.x - window.min.x + 1, window.max.y - window.min.y + 1), {}};
        Imf::FrameBuffer frame_buffer;
        char* base = reinterpret_cast<char*>(result.image.pixels().data());
        const std::size_t row = sizeof(Pixel) * static_cast<std::size_t>(result.image.width());
        for (const ChannelSpec& channel : kChannels) {
            frame_buffer.insert(channel.name,
                                Imf::Slice::Make(channel.memory_type, base + channel.offset, window,
                                                 sizeof(Pixel), row, 1, 1, channel.fill));
        }
        file.setFrameBuffer(frame_buffer);
        file.readPixels(window.min.y, window.max.y);

        ExrMetadata& metadata = result.metadata;
        std::string projection;
        read_attribute<Imf::StringAttribute>(header, "cameraProjection", projection);
        metadata.camera.projection = projection == "orthographic" ? Camera::Projection::Orthographic
                                                                  : Camera::Projection::Pinhole;
        Imath::V3d vector(0.0);
        if (header.findTypedAttribute<Imf::V3dAttribute>("cameraPosition")) {
            read_attribute<Imf::V3dAttribute>(header, "cameraPosition", vector);
            metadata.camera.position = from_imath(vector);
            read_attribute<Imf::V3dAttribute>(header, "cameraLookAt", vector);
            metadata.camera.look_at = from_imath(vector);
            read_attribute<Imf::V3dAttribute>(header, "cameraUp", vector);
            metadata.camera.up = from_imath(vector);
        }
        read_attribute<Imf::DoubleAttribute>(header, "cameraVerticalFov",
                                             metadata.camera.vertical_fov_degrees);
        read_attribute<Imf::DoubleAttribute>(header, "cameraOrthographicHeight",
                                             metadata.camera.orthographic_height);
        read_attribute<Imf::StringAttribute>(header, "accelerator", metadata.accelerator);
        read_attribute<Imf::DoubleAttribute>(header, "acceleratorBuildMs",
                                             metadata.accelerator_build_milliseconds);
        read_attribute<Imf::IntAttribute>(header, "samplesPerPixel", metadata.samples_per_pixel);
        read_attribute<Imf::StringAttribute>(header, "scene", metadata.scene);
        return result;
    } catch (const std::exception& error) {
        throw std::runtime_error("cannot read '" + path.string() + "': " + error.what());
    }
}

std::filesystem::path colour_preview_path(const std::filesystem::path& exr_path) {
    std::filesystem::path path = exr_path;
    return path.replace_extension(".png");
}

std::filesystem::path cost_preview_path(const std::filesystem::path& exr_path) {
    std::filesystem::path path = exr_path;
    return path.replace_extension(".cost.png");
}

void write_render_files(const std::filesystem::path& exr_path, const Image& image,
                        const ExrMetadata& metadata) {
    // A target that is a directory would fail only at its rename, after the others had been
    // replaced: check all three first.
    for (const auto& target :
         {exr_path, colour_preview_path(exr_path), cost_preview_path(exr_path)}) {
        if (std::filesystem::is_directory(target)) {
            throw std::runtime_error("cannot write '" + target.string() + "': is a directory");
        }
    }
    TemporaryFile exr(exr_path);
    TemporaryFile colour(colour_preview_path(exr_path));
    TemporaryFile cost(cost_preview_path(exr_path));
    try {
        write_exr_file(exr.path(), image, metadata);
        write_colour_png(colour.path(), image);
        write_cost_png(cost.path(), image);
    } catch (const std::exception& error) {
        throw std::runtime_error("cannot write '" + exr_path.string() + "': " + error.what());
    }
    exr.commit();
    colour.commit();
    cost.commit();
}

}  // namespace csgrt
