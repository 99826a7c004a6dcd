#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "csgrt/csg/camera.h"
#include "csgrt/render/image.h"
#include "csgrt/render/tonemap.h"

namespace csgrt {

class Scene;

/// A scene object as the EXR's idManifest names it: the id channel's value v means
/// objects[v]. `name` is the object's name, or "object N" (N its index) when it has none.
struct ExrObject {
    std::string name;
    /// Shape::kind() of the object's top shape ("sphere", "difference", "mesh", ...).
    std::string shape;
    std::string material;
};

/// What an EXR written by csgrt records about the render besides its pixels, as header
/// attributes of its first part: the camera (cameraProjection, cameraPosition, cameraLookAt,
/// cameraUp, cameraVerticalFov or cameraOrthographicHeight, and the standard worldToCamera
/// matrix), the resolution (resolution, besides the data window), the structure over the
/// scene's objects (accelerator), samplesPerPixel and the scene's name (scene); and in the id
/// part the standard idManifest naming every object. Timings (acceleratorBuildMs,
/// renderSeconds) are written only when `include_timing` is set, so that identical renders
/// give byte-identical files.
struct ExrMetadata {
    Camera camera;
    std::string accelerator;
    bool include_timing = false;
    double accelerator_build_milliseconds = 0.0;
    double render_seconds = 0.0;
    int samples_per_pixel = 1;
    std::string scene;
    std::vector<ExrObject> objects;
};

/// The idManifest's entries for a committed or uncommitted scene: one per object, in order.
std::vector<ExrObject> exr_objects(const Scene& scene);

/// A csgrt EXR has two parts (OpenEXR 2 multi-part; docs/rendering.md):
/// - "rgba": R, G, B, A as half (linear, premultiplied); Z, N.X, N.Y, N.Z and the cost layer
///   (cost.nodes, cost.primitives, cost.solves, cost.total) as float;
/// - "id": id as uint (kNoIndex = 4294967295 for background), with the idManifest.
/// ZIP compressed, no timestamps. Readers that know one part only (Imf::InputFile) see "rgba".
/// Each of `cost_layers` (csgrt render --cost-all) adds the float channels
/// cost.<structure>.nodes, .primitives, .solves and .total to "rgba", and the header attributes
/// cost.<structure>.buildMilliseconds and .traceMilliseconds (timings: such files differ from
/// run to run).
/// Written to a temporary file in the same directory and renamed over `path`, so `path` is
/// either the old file or the complete new one. Throws std::runtime_error naming the path when
/// it cannot be written.
void write_exr(const std::filesystem::path& path, const Image& image, const ExrMetadata& metadata,
               std::span<const CostLayer> cost_layers = {});

/// An EXR read back: the pixels (colour as stored, i.e. rounded to half) and the metadata.
struct ExrFile {
    Image image;
    ExrMetadata metadata;
    /// The --cost-all layers, in the file's (alphabetical) order.
    std::vector<CostLayer> cost_layers;
};

/// Reads an EXR written by `write_exr` (or by earlier csgrt versions, all channels in one
/// part); channels it lacks keep Pixel's defaults. Throws
/// std::runtime_error naming the path when it cannot be read.
ExrFile read_exr(const std::filesystem::path& path);

/// Writes the EXR at `exr_path` and its two previews beside it: the colour as `stem.png`
/// (write_colour_png with `tone_mapping`) and the cost channel as `stem.cost.png`
/// (write_cost_png, with its scale). All three are written to temporary files first and
/// renamed only when all three are complete; on an error none of them is left half-written and
/// the temporaries are removed. With `cost_layers`, the EXR holds them too and a fourth file,
/// `stem.cost-all.png`, shows them side by side on one scale (write_cost_sheet_png).
void write_render_files(const std::filesystem::path& exr_path, const Image& image,
                        const ExrMetadata& metadata, const ToneMapping& tone_mapping = {},
                        std::span<const CostLayer> cost_layers = {});

/// The preview paths `write_render_files` uses for `exr_path` (out.exr -> out.png,
/// out.cost.png).
std::filesystem::path colour_preview_path(const std::filesystem::path& exr_path);
std::filesystem::path cost_preview_path(const std::filesystem::path& exr_path);
/// out.exr -> out.cost-all.png, the --cost-all contact sheet.
std::filesystem::path cost_sheet_path(const std::filesystem::path& exr_path);
/// Every file write_render_files writes for `exr_path`: the EXR, the two previews and, when
/// asked, the contact sheet.
std::vector<std::filesystem::path> render_file_paths(const std::filesystem::path& exr_path,
                                                     bool with_cost_sheet);

}  // namespace csgrt
