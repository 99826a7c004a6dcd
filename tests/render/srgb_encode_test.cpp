// encode_srgb8 finds its byte in a table of thresholds; these tests hold it to the sRGB
// transfer function evaluated directly (IEC 61966-2-1), computed here independently.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "csgrt/render/png.h"

namespace csgrt {
namespace {

std::uint8_t reference_srgb8(double linear) {
    const double c = linear > 0.0 ? std::min(linear, 1.0) : 0.0;
    const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(std::clamp(encoded, 0.0, 1.0) * 255.0));
}

/// The linear value whose encoding is exactly `encoded` (the inverse transfer function).
double decode(double encoded) {
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

TEST(SrgbEncode, AgreesWithTheDirectFormulaOnEveryRoundingBoundary) {
    // Each code k begins where the encoding crosses (k - 0.5) / 255: the inverse lands within a
    // few ulps of the crossing (two pows, each within 1 ulp), so 64 ulps either side covers it.
    for (int k = 1; k <= 255; ++k) {
        double value = decode((k - 0.5) / 255.0);
        for (int i = 0; i < 64; ++i) value = std::nextafter(value, 0.0);
        for (int i = 0; i < 128; ++i, value = std::nextafter(value, 2.0)) {
            ASSERT_EQ(encode_srgb8(value), reference_srgb8(value)) << "k " << k << " at " << value;
        }
    }
}

TEST(SrgbEncode, AgreesWithTheDirectFormulaOnASweepAndOutOfRange) {
    for (int i = 0; i <= (1 << 18); ++i) {
        const double value = i / double(1 << 18);
        ASSERT_EQ(encode_srgb8(value), reference_srgb8(value)) << value;
    }
    std::mt19937_64 random(13);
    std::uniform_real_distribution<double> uniform(-0.5, 1.5);
    for (int i = 0; i < 100000; ++i) {
        const double value = uniform(random);
        ASSERT_EQ(encode_srgb8(value), reference_srgb8(value)) << value;
    }
    EXPECT_EQ(encode_srgb8(INFINITY), 255);
    EXPECT_EQ(encode_srgb8(-INFINITY), 0);
    EXPECT_EQ(encode_srgb8(std::nan("")), 0);
    EXPECT_EQ(encode_srgb8(1e-300), 0);
}

}  // namespace
}  // namespace csgrt
