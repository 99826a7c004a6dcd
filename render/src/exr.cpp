#include "csgrt/render/exr.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIDManifest.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <tbb/parallel_invoke.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "csgrt/csg/scene.h"
#include "csgrt/render/png.h"
#include "exr_channels.h"
#include "exr_write.h"

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

/// Every channel is a float in memory but the id, whatever its type in the file.
Imf::PixelType memory_type(detail::ExrPixelType type) {
    return type == detail::ExrPixelType::UnsignedInt ? Imf::UINT : Imf::FLOAT;
}

Vector3 from_imath(const Imath::V3d& v) {
    return Vector3(v.x, v.y, v.z);
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
        const std::array<std::string, 4> names = detail::cost_layer_channels(layer.structure);
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
        detail::write_exr_file(temporary.path(), image, metadata, cost_layers);
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
        std::vector<bool> found(detail::kExrChannels.size(), false);
        for (int part = 0; part < file.parts(); ++part) {
            if (file.header(part).dataWindow() != window) continue;
            Imf::FrameBuffer frame_buffer;
            for (std::size_t c = 0; c < detail::kExrChannels.size(); ++c) {
                const detail::ExrChannel& channel = detail::kExrChannels[c];
                if (found[c] || !file.header(part).channels().findChannel(channel.name)) continue;
                if (channel.legacy &&
                    std::any_of(detail::kExrChannels.begin(), detail::kExrChannels.end(),
                                [&](const detail::ExrChannel& current) {
                                    return !current.legacy && current.offset == channel.offset &&
                                           file.header(part).channels().findChannel(current.name);
                                }))
                    continue;
                found[c] = true;
                frame_buffer.insert(channel.name, Imf::Slice::Make(memory_type(channel.file_type),
                                                                   base + channel.offset, window,
                                                                   sizeof(Pixel), row));
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
        // The EXR (its chunks zipped on every thread) beside the previews: they share nothing but
        // the image, which all of them only read.
        tbb::parallel_invoke(
            [&] { detail::write_exr_file(temporaries[0]->path(), image, metadata, cost_layers); },
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
