#include "csgrt/render/png.h"

#include <gtest/gtest.h>
#include <png.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "support/test_output.h"

namespace csgrt {
namespace {

using test::fresh_directory;

/// An 8-bit RGB PNG read with libpng's simplified API.
struct Rgb8 {
    int width = 0, height = 0;
    std::vector<std::uint8_t> data;
    std::array<int, 3> at(int x, int y) const {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
        return {data[i], data[i + 1], data[i + 2]};
    }
};

Rgb8 read_png(const std::filesystem::path& path) {
    png_image image;
    std::memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    EXPECT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << image.message;
    image.format = PNG_FORMAT_RGB;
    Rgb8 result;
    result.width = static_cast<int>(image.width);
    result.height = static_cast<int>(image.height);
    result.data.resize(PNG_IMAGE_SIZE(image));
    EXPECT_TRUE(png_image_finish_read(&image, nullptr, result.data.data(), 0, nullptr))
        << image.message;
    return result;
}

TEST(EncodeSrgb8, MatchesTheSrgbTableAndClamps) {
    // Codes from the IEC 61966-2-1 curve: code 188 is linear 0.5029, code 128 is 0.2159,
    // the linear segment ends at 0.0031308 (code 10.3).
    EXPECT_EQ(encode_srgb8(0.0), 0);
    EXPECT_EQ(encode_srgb8(1.0), 255);
    EXPECT_EQ(encode_srgb8(0.5029), 188);
    EXPECT_EQ(encode_srgb8(0.5), 188);
    EXPECT_EQ(encode_srgb8(0.2159), 128);
    EXPECT_EQ(encode_srgb8(0.0031308), 10);
    EXPECT_EQ(encode_srgb8(0.001), 3);  // 12.92 * 0.001 * 255 = 3.29
    EXPECT_EQ(encode_srgb8(-0.5), 0);
    EXPECT_EQ(encode_srgb8(7.0), 255);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<double>::quiet_NaN()), 0);
    EXPECT_EQ(encode_srgb8(std::numeric_limits<double>::infinity()), 255);
    // Monotone, and every code is reached.
    std::array<bool, 256> seen{};
    int previous = 0;
    for (int i = 0; i <= 100000; ++i) {
        const int code = encode_srgb8(i / 100000.0);
        ASSERT_GE(code, previous);
        previous = code;
        seen[code] = true;
    }
    for (bool reached : seen) EXPECT_TRUE(reached);
}

TEST(Viridis, FollowsMatplotlibsTable) {
    // Entries 0, 64, 128, 192 and 255 of matplotlib's 256-entry viridis table (_cm_listed.py).
    const std::array<std::pair<double, Vector3>, 5> table = {{
        {0.0, Vector3(0.267004, 0.004874, 0.329415)},
        {64.0 / 255.0, Vector3(0.229739, 0.322361, 0.545706)},
        {128.0 / 255.0, Vector3(0.127568, 0.566949, 0.550556)},
        {192.0 / 255.0, Vector3(0.369214, 0.788888, 0.382914)},
        {1.0, Vector3(0.993248, 0.906157, 0.143936)},
    }};
    for (const auto& [t, expected] : table) {
        // The degree-6 fit stays within 0.013 of all 256 entries (measured; 3.3 codes in 8 bits).
        EXPECT_LT((viridis(t) - expected).cwiseAbs().maxCoeff(), 0.013) << "t = " << t;
    }
    EXPECT_EQ(viridis(-3.0), viridis(0.0));
    EXPECT_EQ(viridis(9.0), viridis(1.0));
    // Perceptually ordered: luminance-ish (the green channel) rises monotonically.
    for (int i = 1; i <= 100; ++i) EXPECT_GT(viridis(i / 100.0).y(), viridis((i - 1) / 100.0).y());
}

TEST(WriteColourPng, StoresEachChannelSrgbEncoded) {
    const auto directory = fresh_directory("png_colour");
    Image image(3, 2);
    image.at(0, 0) = Pixel{.red = 1.0f, .green = 0.5f, .blue = 0.0f, .alpha = 1.0f};
    image.at(2, 1) = Pixel{.red = 0.2159f, .green = 4.0f, .blue = -1.0f, .alpha = 1.0f};
    write_colour_png(directory / "c.png", image);
    const Rgb8 png = read_png(directory / "c.png");
    EXPECT_EQ(png.width, 3);
    EXPECT_EQ(png.height, 2);
    EXPECT_EQ(png.at(0, 0), (std::array<int, 3>{255, 188, 0}));
    EXPECT_EQ(png.at(2, 1), (std::array<int, 3>{128, 255, 0}));
    EXPECT_EQ(png.at(1, 0), (std::array<int, 3>{0, 0, 0}));  // background: black
}

TEST(WriteCostPng, NormalisesByTheLargestCost) {
    const auto directory = fresh_directory("png_cost");
    Image image(4, 1);
    image.at(0, 0).cost = 0.0f;
    image.at(1, 0).cost = 10.0f;
    image.at(2, 0).cost = 40.0f;
    image.at(3, 0).cost = 20.0f;
    write_cost_png(directory / "cost.png", image);
    const Rgb8 png = read_png(directory / "cost.png");
    auto code = [](double t) {
        const Vector3 c = viridis(t);
        return std::array<int, 3>{int(std::lround(c.x() * 255)), int(std::lround(c.y() * 255)),
                                  int(std::lround(c.z() * 255))};
    };
    EXPECT_EQ(png.at(0, 0), code(0.0));
    EXPECT_EQ(png.at(1, 0), code(0.25));
    EXPECT_EQ(png.at(2, 0), code(1.0));
    EXPECT_EQ(png.at(3, 0), code(0.5));
    // Viridis ends: dark blue-violet and yellow, within the fit's 3.3 codes of the table's
    // values plus the two roundings to a code (4 codes in all).
    auto near = [](std::array<int, 3> a, std::array<int, 3> b) {
        for (int i = 0; i < 3; ++i) {
            if (std::abs(a[i] - b[i]) > 4) return false;
        }
        return true;
    };
    EXPECT_TRUE(near(png.at(0, 0), {68, 1, 84}));
    EXPECT_TRUE(near(png.at(2, 0), {253, 231, 37}));

    Image flat(2, 2);  // every cost 0: no division by zero, all the low end
    write_cost_png(directory / "flat.png", flat);
    EXPECT_EQ(read_png(directory / "flat.png").at(1, 1), code(0.0));
}

TEST(WriteColourPng, AppliesTheToneMapping) {
    const auto directory = fresh_directory("png_tone_mapped");
    Image image(2, 1);
    image.at(0, 0) = Pixel{.red = 1.0f, .green = 3.0f, .blue = 0.0f, .alpha = 1.0f};
    image.at(1, 0) = Pixel{.red = 1000.0f, .green = 0.25f, .blue = 0.5f, .alpha = 1.0f};
    write_colour_png(directory / "r.png", image, ToneMapping{ToneCurve::Reinhard, 0.0});
    const Rgb8 png = read_png(directory / "r.png");
    // Reinhard: 1 -> 0.5, 3 -> 0.75, 0.25 -> 0.2, each sRGB encoded; 1000 stays below 255.
    EXPECT_EQ(png.at(0, 0), (std::array<int, 3>{encode_srgb8(0.5), encode_srgb8(0.75), 0}));
    EXPECT_EQ(png.at(1, 0)[1], encode_srgb8(0.2));
    EXPECT_EQ(png.at(1, 0)[0], encode_srgb8(1000.0 / 1001.0));
    EXPECT_EQ(png.at(1, 0)[2], encode_srgb8(0.5 / 1.5));
}

TEST(WriteCostPng, DrawsALabelledScaleBelowTheImage) {
    const auto directory = fresh_directory("png_cost_scale");
    Image image(200, 10);
    for (int y = 0; y < 10; ++y) {
        for (int x = 0; x < 200; ++x) image.at(x, y).cost = float(2 * x);  // 0 .. 398
    }
    write_cost_png(directory / "cost.png", image);
    const Rgb8 png = read_png(directory / "cost.png");
    ASSERT_EQ(png.width, 200);
    ASSERT_EQ(png.height, 10 + cost_scale_height(200));
    auto code = [](double t) {
        const Vector3 c = viridis(t);
        return std::array<int, 3>{int(std::lround(c.x() * 255)), int(std::lround(c.y() * 255)),
                                  int(std::lround(c.z() * 255))};
    };
    // The bar runs from viridis(0) at its left end to viridis(1) at its right end, three pixels
    // in from each side (the margin at this width), three rows below the image.
    const int bar_row = 10 + 3 + 5;
    EXPECT_EQ(png.at(3, bar_row), code(0.0));
    EXPECT_EQ(png.at(196, bar_row), code(1.0));
    EXPECT_EQ(png.at(2, bar_row), (std::array<int, 3>{24, 24, 24}));  // the strip's background
    // The numbers are drawn in the light colour in the text rows; count their pixels.
    int lit = 0;
    for (int y = 10 + 3 + 10 + 4; y < png.height; ++y) {
        for (int x = 0; x < 200; ++x) lit += png.at(x, y) == std::array<int, 3>{235, 235, 235};
    }
    EXPECT_GT(lit, 50);
    EXPECT_EQ(cost_label(0.0), "0");
    EXPECT_EQ(cost_label(398.0), "398");
    EXPECT_EQ(cost_label(99.5), "99.5");
    EXPECT_EQ(cost_label(12345.0), "12.3k");
    EXPECT_EQ(cost_label(2.5e6), "2.5M");
}

TEST(WriteCostSheetPng, PutsEveryLayerOnOneScaleUnderItsLabel) {
    const auto directory = fresh_directory("png_cost_sheet");
    // Three 40 x 3 layers whose costs differ by a factor: on one logarithmic scale the first
    // layer's largest cost (10) is log(11) / log(41) of the way up the bar whose end is the
    // third's (40).
    std::vector<CostLayer> layers;
    for (const char* name : {"brute", "grid", "bvh"}) {
        CostLayer layer;
        layer.structure = name;
        layer.build_milliseconds = 1.5;
        layer.width = 40;
        layer.height = 3;
        layer.total.assign(120, 0.0f);
        layers.push_back(layer);
    }
    layers[0].total[0] = 10.0f;
    layers[1].total[41] = 20.0f;   // (1, 1)
    layers[2].total[119] = 40.0f;  // (39, 2)
    write_cost_sheet_png(directory / "sheet.png", layers);
    const Rgb8 png = read_png(directory / "sheet.png");
    const CostSheetLayout layout = cost_sheet_layout(3, 40, 3);
    // Two columns (2^2 >= 3), two rows; the width holds two tiles and the gap between them.
    EXPECT_EQ(layout.columns, 2);
    EXPECT_EQ(layout.rows, 2);
    EXPECT_EQ(layout.width, 80 + layout.gap);
    ASSERT_EQ(png.width, layout.width);
    ASSERT_EQ(png.height, layout.scale_top + cost_scale_height(layout.width));
    auto code = [](double t) {
        const Vector3 c = viridis(t);
        return std::array<int, 3>{int(std::lround(c.x() * 255)), int(std::lround(c.y() * 255)),
                                  int(std::lround(c.z() * 255))};
    };
    auto tile_pixel = [&](int tile, int x, int y) {
        const int left = tile % layout.columns * (40 + layout.gap);
        const int top = tile / layout.columns * (layout.label_height + 3) + layout.label_height;
        return png.at(left + x, top + y);
    };
    EXPECT_EQ(tile_pixel(0, 0, 0), code(std::log(11.0) / std::log(41.0)));
    EXPECT_EQ(tile_pixel(0, 1, 0), code(0.0));
    EXPECT_EQ(tile_pixel(1, 1, 1), code(std::log(21.0) / std::log(41.0)));
    EXPECT_EQ(tile_pixel(2, 39, 2), code(1.0));
    // Each label strip has text in the light colour.
    for (int tile = 0; tile < 3; ++tile) {
        const int left = tile % layout.columns * (40 + layout.gap);
        const int top = tile / layout.columns * (layout.label_height + 3);
        int lit = 0;
        for (int y = top; y < top + layout.label_height; ++y) {
            for (int x = left; x < left + 40; ++x) {
                lit += png.at(x, y) == std::array<int, 3>{235, 235, 235};
            }
        }
        EXPECT_GT(lit, 10) << tile;
    }
    // The scale's bar ends at the largest cost of all layers: viridis(1) at its right end.
    EXPECT_EQ(png.at(layout.width - 4, layout.scale_top + 8), code(1.0));

    EXPECT_EQ(cost_fraction(0.0, 0.0, true), 0.0);
    EXPECT_EQ(cost_fraction(40.0, 40.0, true), 1.0);
    EXPECT_EQ(cost_fraction(10.0, 40.0, false), 0.25);
    EXPECT_THROW(write_cost_sheet_png(directory / "none.png", {}), std::runtime_error);
    layers[1].height = 4;
    EXPECT_THROW(write_cost_sheet_png(directory / "mixed.png", layers), std::runtime_error);
}

TEST(WriteColourPng, ReportsAnUnwritablePath) {
    const auto directory = fresh_directory("png_bad");
    EXPECT_THROW(write_colour_png(directory / "missing" / "c.png", Image(1, 1)),
                 std::runtime_error);
    EXPECT_FALSE(std::filesystem::exists(directory / "missing"));
}

}  // namespace
}  // namespace csgrt
