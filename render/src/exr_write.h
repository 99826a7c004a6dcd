#pragma once

// The EXR writer behind write_exr and write_render_files (render/src only).

#include <filesystem>
#include <span>

#include "csgrt/render/exr.h"

namespace csgrt::detail {

/// Writes the EXR that exr.h documents to `path` (no temporary file: the caller's). Throws
/// std::runtime_error saying what failed.
void write_exr_file(const std::filesystem::path& path, const Image& image,
                    const ExrMetadata& metadata, std::span<const CostLayer> cost_layers);

}  // namespace csgrt::detail
