#pragma once

#include <filesystem>
#include <string>

#include "csgrt/csg/camera.h"
#include "csgrt/render/image.h"

namespace csgrt {

/// What an EXR written by csgrt records about the render besides its pixels, as header
/// attributes: the camera (cameraProjection, cameraPosition, cameraLookAt, cameraUp,
/// cameraVerticalFov or cameraOrthographicHeight, and the standard worldToCamera matrix),
/// the resolution (resolution, besides the data window), the structure over the scene's
/// objects (accelerator, acceleratorBuildMs), samplesPerPixel and the scene's name (scene).
struct ExrMetadata {
    Camera camera;
    std::string accelerator;
    double accelerator_build_milliseconds = 0.0;
    int samples_per_pixel = 1;
    std::string scene;
};

/// The channels of a csgrt EXR: R, G, B, A as half (linear, premultiplied); Z, N.X, N.Y, N.Z
/// and cost as float; id as uint (kNoIndex = 4294967295 for background). ZIP compressed.
/// Written to a temporary file in the same directory and renamed over `path`, so `path` is
/// either the old file or the complete new one. Throws std::runtime_error naming the path when
/// it cannot be written.
void write_exr(const std::filesystem::path& path, const Image& image, const ExrMetadata& metadata);

/// An EXR read back: the pixels (colour as stored, i.e. rounded to half) and the metadata.
struct ExrFile {
    Image image;
    ExrMetadata metadata;
};

/// Reads an EXR written by `write_exr`; channels it lacks keep Pixel's defaults. Throws
/// std::runtime_error naming the path when it cannot be read.
ExrFile read_exr(const std::filesystem::path& path);

/// Writes the EXR at `exr_path` and its two previews beside it: the colour as `stem.png`
/// (png.h) and the cost channel as `stem.cost.png`. All three are written to temporary files
/// first and renamed only when all three are complete; on an error none of them is left
/// half-written and the temporaries are removed.
void write_render_files(const std::filesystem::path& exr_path, const Image& image,
                        const ExrMetadata& metadata);

/// The preview paths `write_render_files` uses for `exr_path` (out.exr -> out.png,
/// out.cost.png).
std::filesystem::path colour_preview_path(const std::filesystem::path& exr_path);
std::filesystem::path cost_preview_path(const std::filesystem::path& exr_path);

}  // namespace csgrt
