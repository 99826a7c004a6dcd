#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
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

/// Where write_cost_sheet_png puts things: `columns` x `rows` tiles (columns the smallest
/// with columns^2 >= tiles), each a label strip of `label_height` rows above a tile of the
/// layers' size, `gap` columns between tiles, and the scale strip from `scale_top` down.
struct CostSheetLayout {
    int columns = 0;
    int rows = 0;
    int gap = 0;
    int label_height = 0;
    int width = 0;
    int height = 0;
    int scale_top = 0;
};
CostSheetLayout cost_sheet_layout(int tiles, int tile_width, int tile_height);

/// Where `cost` lies on a scale from 0 to `max_cost`, in [0, 1]: cost / max_cost, or on a
/// logarithmic scale log(1 + cost) / log(1 + max_cost); 0 when max_cost is 0.
double cost_fraction(double cost, double max_cost, bool logarithmic);

/// Writes the --cost-all contact sheet: each layer's total cost in false colour,
/// viridis(cost_fraction(total, the largest total of all layers, logarithmic)), so the tiles
/// share one scale, logarithmic because structures differ by orders of magnitude (brute force
/// against a hierarchy), under a label naming its structure and build time; below them one
/// scale strip as write_cost_png draws it, its numbers on the logarithmic scale. Tiles go left
/// to right, top to bottom, in the order given. Throws std::runtime_error for no layers or
/// layers of different sizes.
void write_cost_sheet_png(const std::filesystem::path& path, std::span<const CostLayer> layers);

}  // namespace csgrt
