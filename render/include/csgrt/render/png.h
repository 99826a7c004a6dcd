#pragma once

#include <cstdint>
#include <filesystem>

#include "csgrt/core/math.h"
#include "csgrt/render/image.h"

namespace csgrt {

/// A linear value as an 8-bit sRGB code: clamped to [0, 1] (no other tone mapping), encoded
/// with the sRGB transfer function of IEC 61966-2-1 and rounded to the nearest code.
std::uint8_t encode_srgb8(double linear);

/// Matplotlib's perceptually uniform "viridis" ramp at t (clamped to [0, 1]), as display
/// (sRGB-encoded) values in [0, 1]: dark blue at 0, yellow at 1. A degree-6 polynomial fit
/// to the ramp's 256-entry table (Matt Zucker's, CC0), within 0.013 of every entry.
Vector3 viridis(double t);

/// Writes the colour of `image` as an 8-bit RGB PNG: encode_srgb8 of each channel, composited
/// over black (the colour is premultiplied). Writes directly to `path`.
void write_colour_png(const std::filesystem::path& path, const Image& image);

/// Writes the cost channel as an 8-bit RGB false-colour PNG: viridis(cost / max cost) per
/// pixel (all dark blue when every cost is 0). Writes directly to `path`.
void write_cost_png(const std::filesystem::path& path, const Image& image);

}  // namespace csgrt
