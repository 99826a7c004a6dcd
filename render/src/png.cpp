#include "csgrt/render/png.h"

#include <png.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace csgrt {

namespace {

/// Pixels a task of the previews' conversion loops converts: 64K, a few hundred microseconds.
constexpr std::size_t kPixelsPerTask = std::size_t(1) << 16;

void write_rgb8(const std::filesystem::path& path, int width, int height,
                const std::vector<std::uint8_t>& rgb) {
    png_image image;
    std::memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    image.width = static_cast<png_uint_32>(width);
    image.height = static_cast<png_uint_32>(height);
    image.format = PNG_FORMAT_RGB;
    // No row filter and zlib level 3 (libpng's "fast" setting): on a 2048^2 showcase preview
    // 0.04 s of CPU instead of 0.26 s for the adaptive filters at level 6, for a file 1.3x the
    // size (0.59 MB instead of 0.45 MB); the pixels are the same.
    image.flags = PNG_IMAGE_FLAG_FAST;
    // 8-bit formats of libpng's simplified API are sRGB-encoded, which is what we store.
    if (!png_image_write_to_file(&image, path.c_str(), 0, rgb.data(), 0, nullptr)) {
        const std::string message = image.message;
        png_image_free(&image);
        throw std::runtime_error("cannot write PNG '" + path.string() + "': " + message);
    }
}

}  // namespace

namespace {

/// The sRGB transfer function and rounding, evaluated directly (one pow per call).
std::uint8_t encode_srgb8_direct(double linear) {
    // NaN-safe clamp: a NaN becomes 0.
    const double c = linear > 0.0 ? std::min(linear, 1.0) : 0.0;
    const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(std::clamp(encoded, 0.0, 1.0) * 255.0));
}

/// thresholds[k - 1] is the smallest double whose direct encoding is >= k (k = 1..255). The
/// direct encoding never decreases with its input (pow and lround are monotone), so the code of
/// any input is the number of thresholds at or below it: the same byte as encode_srgb8_direct,
/// found by 8 comparisons instead of a pow. A 2048^2 preview took 12.6M pows before.
std::array<double, 255> srgb8_thresholds() {
    std::array<double, 255> thresholds{};
    for (int k = 1; k <= 255; ++k) {
        // Bisection over the bit patterns of the doubles in [0, 1] (ordered like their values).
        std::uint64_t low = 0;  // encodes below k
        std::uint64_t high;     // encodes to >= k
        const double one = 1.0;
        std::memcpy(&high, &one, sizeof(high));
        while (high - low > 1) {
            const std::uint64_t middle = low + (high - low) / 2;
            double value;
            std::memcpy(&value, &middle, sizeof(value));
            (encode_srgb8_direct(value) >= k ? high : low) = middle;
        }
        std::memcpy(&thresholds[k - 1], &high, sizeof(double));
    }
    return thresholds;
}

/// The thresholds, and for each of kSrgb8Buckets equal steps of [0, 1] the code of the step's
/// lower end (the number of thresholds at or below it): a code search starts there and steps
/// up past the thresholds below its input, about one step (the curve rises at most 12.92 * 255
/// codes per unit, 0.8 a bucket).
constexpr int kSrgb8Buckets = 4096;

struct Srgb8Table {
    std::array<double, 255> thresholds;
    std::array<std::uint8_t, kSrgb8Buckets> bucket_code;
};

Srgb8Table srgb8_table() {
    Srgb8Table table{srgb8_thresholds(), {}};
    int code = 0;
    for (int bucket = 0; bucket < kSrgb8Buckets; ++bucket) {
        const double lower = double(bucket) / kSrgb8Buckets;  // exact: a power-of-two divisor
        while (code < 255 && table.thresholds[code] <= lower) ++code;
        table.bucket_code[bucket] = static_cast<std::uint8_t>(code);
    }
    return table;
}

}  // namespace

std::uint8_t encode_srgb8(double linear) {
    static const Srgb8Table kTable = srgb8_table();
    // A NaN or anything at or below 0 is 0, as in the direct encoding; 1 and above is 255 (the
    // last threshold is at most 1, which encodes to 255).
    if (!(linear > 0.0)) return 0;
    if (linear >= 1.0) return 255;
    // linear * kSrgb8Buckets is exact, so its floor is the bucket whose lower end is <= linear.
    int code = kTable.bucket_code[static_cast<int>(linear * kSrgb8Buckets)];
    while (code < 255 && linear >= kTable.thresholds[code]) ++code;
    return static_cast<std::uint8_t>(code);
}

namespace {

/// viridis(t) as 8-bit sRGB codes.
std::array<std::uint8_t, 3> viridis8(double t) {
    const Vector3 colour = viridis(t);
    return {static_cast<std::uint8_t>(std::lround(colour.x() * 255.0)),
            static_cast<std::uint8_t>(std::lround(colour.y() * 255.0)),
            static_cast<std::uint8_t>(std::lround(colour.z() * 255.0))};
}

/// viridis8(cost / max_cost) (0 when max_cost is 0) for each pixel's cost. Costs are counts,
/// so the colours of the whole numbers up to the largest cost are computed once and looked up
/// when there are few of them (at most a quarter of the `pixels` to colour, and 2^20); any
/// other cost is computed as it comes. Same bytes either way: the table holds the same
/// expression of the same value.
class CostColours {
public:
    CostColours(float max_cost, std::size_t pixels) : max_cost_(max_cost) {
        const double most = std::min(double(pixels / 4), double(kMaxCostColours));
        if (!(max_cost >= 0.0f && double(max_cost) <= most)) return;
        table_.resize(static_cast<std::size_t>(max_cost) + 1);
        for (std::size_t cost = 0; cost < table_.size(); ++cost) table_[cost] = direct(float(cost));
    }

    std::array<std::uint8_t, 3> operator()(float cost) const {
        if (cost >= 0.0f && cost < float(table_.size())) {
            const auto whole = static_cast<std::size_t>(cost);
            if (float(whole) == cost) return table_[whole];
        }
        return direct(cost);
    }

private:
    static constexpr int kMaxCostColours = 1 << 20;

    std::array<std::uint8_t, 3> direct(float cost) const {
        return viridis8(max_cost_ > 0.0f ? double(cost) / max_cost_ : 0.0);
    }

    float max_cost_;
    std::vector<std::array<std::uint8_t, 3>> table_;
};

}  // namespace

Vector3 viridis(double t) {
    // Horner form of the degree-6 minimax fit; coefficients by Matt Zucker
    // (https://www.shadertoy.com/view/WlfXRN, CC0), fitted to matplotlib's table.
    static const std::array<Vector3, 7> kCoefficients = {
        Vector3(0.2777273272234177, 0.005407344544966578, 0.3340998053353061),
        Vector3(0.1050930431085774, 1.404613529898575, 1.384590162594685),
        Vector3(-0.3308618287255563, 0.214847559468213, 0.09509516302823659),
        Vector3(-4.634230498983486, -5.799100973351585, -19.33244095627987),
        Vector3(6.228269936347081, 14.17993336680509, 56.69055260068105),
        Vector3(4.776384997670288, -13.74514537774601, -65.35303263337234),
        Vector3(-5.435455855934631, 4.645852612178535, 26.3124352495832),
    };
    const double x = t > 0.0 ? std::min(t, 1.0) : 0.0;
    Vector3 value = kCoefficients[6];
    for (int k = 5; k >= 0; --k) value = kCoefficients[k] + x * value;
    return value.cwiseMax(0.0).cwiseMin(1.0);
}

void write_colour_png(const std::filesystem::path& path, const Image& image,
                      const ToneMapping& mapping) {
    std::vector<std::uint8_t> rgb(3 * image.pixel_count());
    const ToneMapper tone(mapping);
    const Image::Pixels& pixels = image.pixels();
    // Rows in parallel: each byte depends on its own pixel only.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels.size(), kPixelsPerTask),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i) {
                              const Pixel& pixel = pixels[i];
                              rgb[3 * i] = encode_srgb8(tone(pixel.red));
                              rgb[3 * i + 1] = encode_srgb8(tone(pixel.green));
                              rgb[3 * i + 2] = encode_srgb8(tone(pixel.blue));
                          }
                      });
    write_rgb8(path, image.width(), image.height(), rgb);
}

namespace {

/// A 5 x 7 pixel font for the scale's numbers: each glyph is 7 rows of 5 bits, the high bit left.
struct Glyph {
    char character;
    std::array<std::uint8_t, 7> rows;
};

constexpr std::array<Glyph, 39> kGlyphs = {{
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
    {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
    {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
    {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
    {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
    {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    // Lower case, for the contact sheet's structure names (no descenders: 7 rows).
    {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}},
    {'b', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E}},
    {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}},
    {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}},
    {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}},
    {'g', {0x00, 0x00, 0x0F, 0x11, 0x0F, 0x01, 0x0E}},
    {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}},
    {'j', {0x02, 0x00, 0x06, 0x02, 0x02, 0x12, 0x0C}},
    {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}},
    {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'m', {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}},
    {'p', {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}},
    {'q', {0x00, 0x00, 0x0D, 0x13, 0x0F, 0x01, 0x01}},
    {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}},
    {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}},
    {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'w', {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A}},
    {'x', {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}},
    {'y', {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E}},
    {'z', {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F}},
}};

/// An RGB8 canvas that clips what is drawn outside it.
struct Canvas {
    int width;
    int height;
    std::vector<std::uint8_t>& rgb;

    void set(int x, int y, const std::array<std::uint8_t, 3>& colour) {
        if (x < 0 || y < 0 || x >= width || y >= height) return;
        const std::size_t at = 3 * (static_cast<std::size_t>(y) * width + x);
        for (int c = 0; c < 3; ++c) rgb[at + c] = colour[c];
    }
    void fill(int x0, int y0, int x1, int y1, const std::array<std::uint8_t, 3>& colour) {
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) set(x, y, colour);
        }
    }
    /// `text` with its top-left corner at (x, y), each font pixel `scale` x `scale`.
    void text(int x, int y, const std::string& text, int scale,
              const std::array<std::uint8_t, 3>& colour) {
        for (char character : text) {
            for (const Glyph& glyph : kGlyphs) {
                if (glyph.character != character) continue;
                for (int row = 0; row < 7; ++row) {
                    for (int column = 0; column < 5; ++column) {
                        if (!(glyph.rows[row] & (0x10 >> column))) continue;
                        fill(x + column * scale, y + row * scale, x + (column + 1) * scale,
                             y + (row + 1) * scale, colour);
                    }
                }
            }
            x += 6 * scale;
        }
    }
};

/// The scale's font pixel size: 1 up to 511 pixels wide, growing with wider images.
int scale_unit(int width) {
    return std::max(1, width / 512 + 1);
}

}  // namespace

int cost_scale_height(int width) {
    // Margin 3, bar 10, tick 3, gap 1, numbers 7, margin 3 (font pixels).
    return 27 * scale_unit(width);
}

std::string cost_label(double value) {
    if (!(value > 0.0)) return "0";
    char text[32];
    const char* suffix = "";
    if (value >= 1e6) {
        value /= 1e6;
        suffix = "M";
    } else if (value >= 1e4) {
        value /= 1e3;
        suffix = "k";
    }
    if (value >= 100.0 && suffix[0] == '\0') {
        std::snprintf(text, sizeof(text), "%.0f", value);
    } else {
        std::snprintf(text, sizeof(text), "%.3g%s", value, suffix);
    }
    return text;
}

namespace {

/// Draws the scale strip (cost_scale_height(canvas.width) rows from `top`): a dark band, the
/// colour bar from 0 (left) to `max_cost` (right), five ticks with their numbers, the outer two
/// aligned to the bar's ends so that they stay in frame. On a `logarithmic` scale the bar's
/// fraction t stands for the cost (1 + max_cost)^t - 1 (cost_fraction's inverse).
void draw_cost_scale(Canvas& canvas, int top, float max_cost, bool logarithmic) {
    const int width = canvas.width;
    const int unit = scale_unit(width);
    const std::array<std::uint8_t, 3> dark = {24, 24, 24};
    const std::array<std::uint8_t, 3> white = {235, 235, 235};
    canvas.fill(0, top, width, top + cost_scale_height(width), dark);
    const int margin = std::min(3 * unit, std::max(0, (width - 2) / 2));
    const int bar_left = margin;
    const int bar_right = width - margin;  // exclusive
    const int bar_top = top + 3 * unit;
    for (int x = bar_left; x < bar_right; ++x) {
        const double t =
            bar_right - bar_left > 1 ? double(x - bar_left) / (bar_right - bar_left - 1) : 0.0;
        canvas.fill(x, bar_top, x + 1, bar_top + 10 * unit, viridis8(t));
    }
    const int tick_top = bar_top + 10 * unit;
    const int text_top = tick_top + 4 * unit;
    // The ends first, then the middle, then the quarters: a number that would overlap one
    // already written (a narrow image) is left out, its tick kept.
    std::vector<std::pair<int, int>> written;
    for (int k : {0, 4, 2, 1, 3}) {
        const int x = bar_left + (bar_right - 1 - bar_left) * k / 4;
        canvas.fill(x - (unit - 1) / 2, tick_top, x + unit / 2 + 1, tick_top + 3 * unit, white);
        const std::string label = cost_label(
            logarithmic ? std::expm1(std::log1p(double(max_cost)) * k / 4.0) : max_cost * k / 4.0);
        const int text_width = static_cast<int>(label.size()) * 6 * unit - unit;
        int text_left = x - text_width / 2;
        if (k == 0) text_left = bar_left;
        if (k == 4) text_left = bar_right - text_width;
        const int text_right = text_left + text_width;
        const bool overlaps = std::any_of(written.begin(), written.end(), [&](const auto& span) {
            return text_left < span.second + 2 * unit && span.first < text_right + 2 * unit;
        });
        if (overlaps) continue;
        written.emplace_back(text_left, text_right);
        canvas.text(text_left, text_top, label, unit, white);
    }
}

}  // namespace

void write_cost_png(const std::filesystem::path& path, const Image& image) {
    float max_cost = 0.0f;
    for (const Pixel& pixel : image.pixels()) max_cost = std::max(max_cost, pixel.cost);
    const int width = image.width();
    const int height = image.height() + cost_scale_height(width);
    std::vector<std::uint8_t> rgb(3 * static_cast<std::size_t>(width) * height, 0);
    Canvas canvas{width, height, rgb};
    const CostColours colours(max_cost, image.pixel_count());
    const Image::Pixels& pixels = image.pixels();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels.size(), kPixelsPerTask),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i) {
                              const std::array<std::uint8_t, 3> colour = colours(pixels[i].cost);
                              std::copy(colour.begin(), colour.end(), rgb.begin() + 3 * i);
                          }
                      });
    draw_cost_scale(canvas, image.height(), max_cost, false);
    write_rgb8(path, width, height, rgb);
}

double cost_fraction(double cost, double max_cost, bool logarithmic) {
    if (!(max_cost > 0.0) || !(cost > 0.0)) return 0.0;
    return logarithmic ? std::log1p(cost) / std::log1p(max_cost) : cost / max_cost;
}

CostSheetLayout cost_sheet_layout(int tiles, int tile_width, int tile_height) {
    CostSheetLayout layout;
    layout.columns = 1;
    while (layout.columns * layout.columns < tiles) ++layout.columns;
    layout.rows = tiles > 0 ? (tiles + layout.columns - 1) / layout.columns : 0;
    const int provisional = layout.columns * tile_width;
    const int unit = scale_unit(provisional);
    layout.gap = 2 * unit;
    layout.label_height = 11 * unit;
    layout.width = layout.columns * tile_width + (layout.columns - 1) * layout.gap;
    layout.scale_top = layout.rows * (layout.label_height + tile_height);
    layout.height = layout.scale_top + cost_scale_height(layout.width);
    return layout;
}

void write_cost_sheet_png(const std::filesystem::path& path, std::span<const CostLayer> layers) {
    if (layers.empty())
        throw std::runtime_error("cannot write '" + path.string() +
                                 "': a contact sheet needs a cost layer");
    const int tile_width = layers.front().width;
    const int tile_height = layers.front().height;
    float max_cost = 0.0f;
    for (const CostLayer& layer : layers) {
        if (layer.width != tile_width || layer.height != tile_height ||
            layer.total.size() != std::size_t(tile_width) * std::size_t(tile_height)) {
            throw std::runtime_error("cannot write '" + path.string() + "': cost layer '" +
                                     layer.structure + "' differs in size from the first");
        }
        for (const float cost : layer.total) max_cost = std::max(max_cost, cost);
    }
    const CostSheetLayout layout =
        cost_sheet_layout(static_cast<int>(layers.size()), tile_width, tile_height);
    std::vector<std::uint8_t> rgb(3 * static_cast<std::size_t>(layout.width) * layout.height, 0);
    Canvas canvas{layout.width, layout.height, rgb};
    const std::array<std::uint8_t, 3> dark = {24, 24, 24};
    const std::array<std::uint8_t, 3> white = {235, 235, 235};
    canvas.fill(0, 0, layout.width, layout.scale_top, dark);
    const int unit = layout.label_height / 11;
    for (std::size_t i = 0; i < layers.size(); ++i) {
        const CostLayer& layer = layers[i];
        const int left = static_cast<int>(i) % layout.columns * (tile_width + layout.gap);
        const int top = static_cast<int>(i) / layout.columns * (layout.label_height + tile_height);
        // The label: the structure and its build time, or the name alone when both do not fit.
        char built[32];
        std::snprintf(built, sizeof(built),
                      layer.build_milliseconds < 100.0 ? " %.3g ms" : " %.0f ms",
                      layer.build_milliseconds);
        std::string label = layer.structure + built;
        if (static_cast<int>(label.size()) * 6 * unit > tile_width) label = layer.structure;
        canvas.text(left + unit, top + 2 * unit, label, unit, white);
        for (int y = 0; y < tile_height; ++y) {
            for (int x = 0; x < tile_width; ++x) {
                const float cost = layer.total[std::size_t(y) * tile_width + x];
                canvas.set(left + x, top + layout.label_height + y,
                           viridis8(cost_fraction(cost, max_cost, true)));
            }
        }
    }
    draw_cost_scale(canvas, layout.scale_top, max_cost, true);
    write_rgb8(path, layout.width, layout.height, rgb);
}

}  // namespace csgrt
