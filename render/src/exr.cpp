#include "csgrt/render/exr.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIDManifest.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <tbb/parallel_invoke.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <vector>

#include "csgrt/csg/scene.h"
#include "csgrt/render/png.h"
#include "exr_id_manifest.h"

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
    /// The part it is written to: 0 (kImagePart) or 1 (kIdPart).
    int part;
    Imf::PixelType file_type;
    Imf::PixelType memory_type;
    std::size_t offset;
    double fill;
    /// Read from files of earlier csgrt versions when the file lacks the channel that now
    /// holds the value; never written.
    bool legacy = false;
};

constexpr int kImagePart = 0;
constexpr int kIdPart = 1;
const std::array<const char*, 2> kPartNames = {"rgba", "id"};

// The channels in file order, with their part, where each lives in a Pixel and what a missing
// one reads as; the half channels come first, in the order of the write buffer. The id has a
// part of its own: OpenImageIO gives a part one pixel type, and in a part of mixed types it
// converts a uint channel to float normalised by 2^32 - 1, which loses the ids.
// The cost is the layer "cost" with one channel per count (Nuke's and OpenImageIO's
// layer.channel rule: the last dot separates them); earlier files had one channel "cost".
const std::array<ChannelSpec, 14> kChannels = {{
    {"R", kImagePart, Imf::HALF, Imf::FLOAT, offsetof(Pixel, red), 0.0},
    {"G", kImagePart, Imf::HALF, Imf::FLOAT, offsetof(Pixel, green), 0.0},
    {"B", kImagePart, Imf::HALF, Imf::FLOAT, offsetof(Pixel, blue), 0.0},
    {"A", kImagePart, Imf::HALF, Imf::FLOAT, offsetof(Pixel, alpha), 0.0},
    {"Z", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, depth), kInfinity},
    {"N.X", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, normal_x), 0.0},
    {"N.Y", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, normal_y), 0.0},
    {"N.Z", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, normal_z), 0.0},
    {"cost.nodes", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, cost_nodes), 0.0},
    {"cost.primitives", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, cost_primitives), 0.0},
    {"cost.solves", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, cost_solves), 0.0},
    {"cost.total", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, cost), 0.0},
    {"cost", kImagePart, Imf::FLOAT, Imf::FLOAT, offsetof(Pixel, cost), 0.0, true},
    {"id", kIdPart, Imf::UINT, Imf::UINT, offsetof(Pixel, object_id), double(kNoIndex)},
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

/// zlib's fastest level. A 2048^2 showcase frame is 185 MB of channels; zipping them took
/// 2.0 s of CPU at OpenEXR's default level 4 and takes 1.3 s at level 1, for a file 4% larger
/// (24.4 MB instead of 23.3 MB). The pixels read back are the same at any level.
constexpr int kZipLevel = 1;

/// The names of a cost layer's channels, in Pixel's order: "cost.<structure>.nodes", ...
std::array<std::string, 4> cost_layer_channels(const std::string& structure) {
    const std::string prefix = "cost." + structure + ".";
    return {prefix + "nodes", prefix + "primitives", prefix + "solves", prefix + "total"};
}

std::array<const std::vector<float>*, 4> channels_of(const CostLayer& layer) {
    return {&layer.nodes, &layer.primitives, &layer.solves, &layer.total};
}

void write_exr_file(const std::filesystem::path& path, const Image& image,
                    const ExrMetadata& metadata, std::span<const CostLayer> cost_layers) {
    std::vector<Imf::Header> headers(kPartNames.size(), Imf::Header(image.width(), image.height()));
    for (std::size_t part = 0; part < headers.size(); ++part) {
        headers[part].setName(kPartNames[part]);
        headers[part].setType(Imf::SCANLINEIMAGE);
        headers[part].compression() = Imf::ZIP_COMPRESSION;
        headers[part].zipCompressionLevel() = kZipLevel;
    }
    for (const ChannelSpec& channel : kChannels) {
        if (channel.legacy) continue;
        headers[channel.part].channels().insert(channel.name, Imf::Channel(channel.file_type));
    }
    Imf::Header& header = headers[kImagePart];
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
    // Timings differ from run to run: only when asked, so identical renders give identical files.
    if (metadata.include_timing) {
        header.insert("acceleratorBuildMs",
                      Imf::DoubleAttribute(metadata.accelerator_build_milliseconds));
        header.insert("renderSeconds", Imf::DoubleAttribute(metadata.render_seconds));
    }
    header.insert("samplesPerPixel", Imf::IntAttribute(metadata.samples_per_pixel));
    header.insert("scene", Imf::StringAttribute(metadata.scene));
    // --cost-all: one layer per structure, its build time beside it (a timing, asked for).
    for (const CostLayer& layer : cost_layers) {
        if (layer.width != image.width() || layer.height != image.height()) {
            throw std::runtime_error("cost layer '" + layer.structure + "' is " +
                                     std::to_string(layer.width) + "x" +
                                     std::to_string(layer.height) + ", not the image's size");
        }
        for (const std::string& name : cost_layer_channels(layer.structure)) {
            header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        }
        header.insert("cost." + layer.structure + ".buildMilliseconds",
                      Imf::DoubleAttribute(layer.build_milliseconds));
        header.insert("cost." + layer.structure + ".traceMilliseconds",
                      Imf::DoubleAttribute(layer.trace_milliseconds));
    }
    Imf::addIDManifest(headers[kIdPart], detail::id_manifest(metadata, kZipLevel));

    // OpenEXR converts pixel types when reading but not when writing: the colour channels go
    // through a half buffer (R, G, B, A interleaved).
    std::vector<std::array<half, 4>> colour(image.pixel_count());
    for (std::size_t i = 0; i < colour.size(); ++i) {
        const Pixel& pixel = image.pixels()[i];
        colour[i] = {half(pixel.red), half(pixel.green), half(pixel.blue), half(pixel.alpha)};
    }
    std::vector<Imf::FrameBuffer> frame_buffers(kPartNames.size());
    const char* base = reinterpret_cast<const char*>(image.pixels().data());
    const std::size_t row = sizeof(Pixel) * static_cast<std::size_t>(image.width());
    const std::size_t colour_row = sizeof(colour[0]) * static_cast<std::size_t>(image.width());
    for (std::size_t c = 0; c < kChannels.size(); ++c) {
        const ChannelSpec& channel = kChannels[c];
        if (channel.legacy) continue;
        Imf::FrameBuffer& frame_buffer = frame_buffers[channel.part];
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
    const std::size_t float_row = sizeof(float) * static_cast<std::size_t>(image.width());
    for (const CostLayer& layer : cost_layers) {
        const std::array<std::string, 4> names = cost_layer_channels(layer.structure);
        const auto channels = channels_of(layer);
        for (std::size_t c = 0; c < names.size(); ++c) {
            char* data = reinterpret_cast<char*>(const_cast<float*>(channels[c]->data()));
            frame_buffers[kImagePart].insert(
                names[c], Imf::Slice(Imf::FLOAT, data, sizeof(float), float_row));
        }
    }
    // OpenEXR zips its 16-line chunks on its own thread pool when it has one; without, a 2048^2
    // frame's zlib work runs on one core. The chunks are independent and written in line order,
    // so the file's bytes do not depend on the thread count. Set once for the process, and only
    // if the program has not chosen a count itself.
    static const bool kThreadsChosen = [] {
        if (Imf::globalThreadCount() == 0) {
            Imf::setGlobalThreadCount(static_cast<int>(std::thread::hardware_concurrency()));
        }
        return true;
    }();
    static_cast<void>(kThreadsChosen);
    Imf::MultiPartOutputFile file(path.c_str(), headers.data(), static_cast<int>(headers.size()));
    for (std::size_t part = 0; part < headers.size(); ++part) {
        Imf::OutputPart output(file, static_cast<int>(part));
        output.setFrameBuffer(frame_buffers[part]);
        output.writePixels(image.height());
    }
}

/// The --cost-all layers of the first part: every channel "cost.<structure>.total" names one.
void read_cost_layers(Imf::MultiPartInputFile& file, ExrFile& result) {
    const Imf::Header& header = file.header(0);
    const int width = result.image.width();
    const int height = result.image.height();
    const std::string suffix = ".total";
    Imf::FrameBuffer frame_buffer;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        const std::string name = it.name();
        if (!name.starts_with("cost.") || !name.ends_with(suffix) || name == "cost.total") continue;
        CostLayer layer;
        layer.structure = name.substr(5, name.size() - 5 - suffix.size());
        layer.width = width;
        layer.height = height;
        if (const auto* built = header.findTypedAttribute<Imf::DoubleAttribute>(
                "cost." + layer.structure + ".buildMilliseconds")) {
            layer.build_milliseconds = built->value();
        }
        if (const auto* traced = header.findTypedAttribute<Imf::DoubleAttribute>(
                "cost." + layer.structure + ".traceMilliseconds")) {
            layer.trace_milliseconds = traced->value();
        }
        result.cost_layers.push_back(std::move(layer));
    }
    const Imath::Box2i window = header.dataWindow();
    for (CostLayer& layer : result.cost_layers) {
        const std::array<std::string, 4> names = cost_layer_channels(layer.structure);
        const std::array<std::vector<float>*, 4> channels = {&layer.nodes, &layer.primitives,
                                                             &layer.solves, &layer.total};
        for (std::size_t c = 0; c < names.size(); ++c) {
            channels[c]->assign(std::size_t(width) * std::size_t(height), 0.0f);
            if (!header.channels().findChannel(names[c])) continue;
            frame_buffer.insert(names[c], Imf::Slice::Make(Imf::FLOAT, channels[c]->data(), window,
                                                           sizeof(float), sizeof(float) * width));
        }
    }
    if (result.cost_layers.empty()) return;
    Imf::InputPart input(file, 0);
    input.setFrameBuffer(frame_buffer);
    input.readPixels(window.min.y, window.max.y);
}

template <class Attribute, class Value>
void read_attribute(const Imf::Header& header, const char* name, Value& value) {
    if (const auto* attribute = header.findTypedAttribute<Attribute>(name)) {
        value = attribute->value();
    }
}

}  // namespace

void write_exr(const std::filesystem::path& path, const Image& image, const ExrMetadata& metadata,
               std::span<const CostLayer> cost_layers) {
    TemporaryFile temporary(path);
    try {
        write_exr_file(temporary.path(), image, metadata, cost_layers);
    } catch (const std::exception& error) {
        throw std::runtime_error("cannot write '" + path.string() + "': " + error.what());
    }
    temporary.commit();
}

ExrFile read_exr(const std::filesystem::path& path) {
    try {
        Imf::MultiPartInputFile file(path.c_str());
        // Earlier csgrt files are one part; the channels are looked up by name in every part.
        const Imf::Header& header = file.header(0);
        const Imath::Box2i window = header.dataWindow();
        ExrFile result{
            Image(window.max.x - window.min.x + 1, window.max.y - window.min.y + 1), {}, {}};
        char* base = reinterpret_cast<char*>(result.image.pixels().data());
        const std::size_t row = sizeof(Pixel) * static_cast<std::size_t>(result.image.width());
        std::vector<bool> found(kChannels.size(), false);
        for (int part = 0; part < file.parts(); ++part) {
            if (file.header(part).dataWindow() != window) continue;
            Imf::FrameBuffer frame_buffer;
            for (std::size_t c = 0; c < kChannels.size(); ++c) {
                const ChannelSpec& channel = kChannels[c];
                if (found[c] || !file.header(part).channels().findChannel(channel.name)) continue;
                if (channel.legacy &&
                    std::any_of(kChannels.begin(), kChannels.end(),
                                [&](const ChannelSpec& current) {
                                    return !current.legacy && current.offset == channel.offset &&
                                           file.header(part).channels().findChannel(current.name);
                                }))
                    continue;
                found[c] = true;
                frame_buffer.insert(channel.name,
                                    Imf::Slice::Make(channel.memory_type, base + channel.offset,
                                                     window, sizeof(Pixel), row));
            }
            Imf::InputPart input(file, part);
            input.setFrameBuffer(frame_buffer);
            input.readPixels(window.min.y, window.max.y);
        }
        // Channels no part has keep Pixel's defaults, which the Image already holds.
        read_cost_layers(file, result);

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
        metadata.include_timing =
            header.findTypedAttribute<Imf::DoubleAttribute>("acceleratorBuildMs") != nullptr;
        read_attribute<Imf::DoubleAttribute>(header, "acceleratorBuildMs",
                                             metadata.accelerator_build_milliseconds);
        read_attribute<Imf::DoubleAttribute>(header, "renderSeconds", metadata.render_seconds);
        read_attribute<Imf::IntAttribute>(header, "samplesPerPixel", metadata.samples_per_pixel);
        read_attribute<Imf::StringAttribute>(header, "scene", metadata.scene);
        for (int part = 0; part < file.parts(); ++part) {
            if (!Imf::hasIDManifest(file.header(part))) continue;
            const Imf::IDManifest manifest(Imf::idManifest(file.header(part)));
            const std::size_t group = manifest.find("id");
            if (group >= manifest.size()) continue;
            for (auto entry = manifest[group].begin(); entry != manifest[group].end(); ++entry) {
                const std::vector<std::string>& text = entry.text();
                if (entry.id() >= kNoIndex) continue;
                if (metadata.objects.size() <= entry.id()) metadata.objects.resize(entry.id() + 1);
                ExrObject& object = metadata.objects[entry.id()];
                if (text.size() > 0) object.name = text[0];
                if (text.size() > 1) object.shape = text[1];
                if (text.size() > 2) object.material = text[2];
            }
        }
        return result;
    } catch (const std::exception& error) {
        throw std::runtime_error("cannot read '" + path.string() + "': " + error.what());
    }
}

std::vector<ExrObject> exr_objects(const Scene& scene) {
    std::vector<ExrObject> objects;
    objects.reserve(scene.objects().size());
    for (std::size_t i = 0; i < scene.objects().size(); ++i) {
        const SceneObject& object = scene.objects()[i];
        ExrObject entry;
        entry.name = object.name.empty() ? "object " + std::to_string(i) : object.name;
        entry.shape = std::string(object.shape->kind());
        if (object.material < scene.materials().size()) {
            entry.material = scene.materials()[object.material].name;
        }
        objects.push_back(std::move(entry));
    }
    return objects;
}

std::filesystem::path colour_preview_path(const std::filesystem::path& exr_path) {
    std::filesystem::path path = exr_path;
    return path.replace_extension(".png");
}

std::filesystem::path cost_preview_path(const std::filesystem::path& exr_path) {
    std::filesystem::path path = exr_path;
    return path.replace_extension(".cost.png");
}

std::filesystem::path cost_sheet_path(const std::filesystem::path& exr_path) {
    std::filesystem::path path = exr_path;
    return path.replace_extension(".cost-all.png");
}

std::vector<std::filesystem::path> render_file_paths(const std::filesystem::path& exr_path,
                                                     bool with_cost_sheet) {
    std::vector<std::filesystem::path> paths = {exr_path, colour_preview_path(exr_path),
                                                cost_preview_path(exr_path)};
    if (with_cost_sheet) paths.push_back(cost_sheet_path(exr_path));
    return paths;
}

void write_render_files(const std::filesystem::path& exr_path, const Image& image,
                        const ExrMetadata& metadata, const ToneMapping& tone_mapping,
                        std::span<const CostLayer> cost_layers) {
    // A target that is a directory would fail only at its rename, after the others had been
    // replaced: check them all first.
    const std::vector<std::filesystem::path> targets =
        render_file_paths(exr_path, !cost_layers.empty());
    for (const auto& target : targets) {
        if (std::filesystem::is_directory(target)) {
            throw std::runtime_error("cannot write '" + target.string() + "': is a directory");
        }
    }
    std::vector<std::unique_ptr<TemporaryFile>> temporaries;
    for (const auto& target : targets)
        temporaries.push_back(std::make_unique<TemporaryFile>(target));
    try {
        // The EXR (zipped on OpenEXR's threads) beside the previews: they share nothing but
        // the image, which all of them only read.
        tbb::parallel_invoke(
            [&] { write_exr_file(temporaries[0]->path(), image, metadata, cost_layers); },
            [&] {
                write_colour_png(temporaries[1]->path(), image, tone_mapping);
                write_cost_png(temporaries[2]->path(), image);
                if (!cost_layers.empty()) write_cost_sheet_png(temporaries[3]->path(), cost_layers);
            });
    } catch (const std::exception& error) {
        throw std::runtime_error("cannot write '" + exr_path.string() + "': " + error.what());
    }
    for (const auto& temporary : temporaries) temporary->commit();
}

}  // namespace csgrt
