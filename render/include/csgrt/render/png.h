#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "csgrt/core/math.h"
#include "csgrt/render/image.h"
#include "csgrt/render/tonemap.h"

namespace csgrt {

/// A linear value as an 8-bit sRGB code: clamped to [0, 1] (no other tone mapping), encoded
/// with the sRGB transfer function of IEC 61966-2-1 and rounded to the nearest code.
std::uint8_t encode_srgb8(double linear);

/// Matplotlib's perceptually uniform "viridis" ramp at t (clamped to [0, 1]), as display
/// (sRGB-encoded) values in [0, 1]: dark blue at 0, yellow at 1. A degree-6 polynomial fit
/// to the ramp's 256-entry table (Matt Zucker's, CC0), within 0.013 of every entry.
Vector3 viridis(double t);

/// Writes the colour of `image` as an 8-bit RGB PNG: each channel composited over black (the
/// colour is premultiplied), tone mapped by `mapping` (tonemap.h) and sRGB encoded with
/// encode_srgb8. The default, a plain clamp, is the unmapped preview; the program passes its
/// --tonemap and --exposure. Writes directly to `path`.
void write_colour_png(const std::filesystem::path& path, const Image& image,
                      const ToneMapping& mapping = ToneMapping{ToneCurve::Clamp, 0.0});

/// Height in pixels of the scale strip write_cost_png adds below an image `width` wide.
int cost_scale_height(int width);

/// The numbers written on the cost scale: `value` with at most three significant digits, as
/// an integer below 10,000 and with a k or M suffix above ("0", "12.5", "480", "12.3k").
std::string cost_label(double value);

/// Writes the cost channel as an 8-bit RGB false-colour PNG: viridis(cost / max cost) per
/// pixel (all dark blue when every cost is 0), and below the image a strip of
/// cost_scale_height(width) rows with the scale: a colour bar from 0 to the largest cost with
/// ticks and numbers (cost_label) at 0, 1/4, 1/2, 3/4 and 1 of it. Writes directly to `path`.
void write_cost_png(const std::filesystem::path& path, const Image& image);

}  // namespace csgrt
