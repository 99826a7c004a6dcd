#include "csgrt/render/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "csgrt/core/error.h"

namespace csgrt {
namespace {

TEST(SampleRandom, MatchesTheSplitMix64ReferenceSequence) {
    // The first outputs of SplitMix64 seeded with 0, as in Vigna's reference splitmix64.c.
    SampleRandom random(0);
    EXPECT_EQ(random.next_bits(), 0xe220a8397b1dcdafull);
    EXPECT_EQ(random.next_bits(), 0x6e789e6aa1b965f4ull);
    EXPECT_EQ(random.next_bits(), 0x06c45d188009454full);
}

TEST(SampleRandom, UniformIsInTheHalfOpenUnitIntervalAndFlat) {
    SampleRandom random(12345);
    constexpr int kDraws = 200000, kBins = 20;
    std::vector<int> bins(kBins, 0);
    double sum = 0.0;
    for (int i = 0; i < kDraws; ++i) {
        const double u = random.uniform();
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        sum += u;
        ++bins[static_cast<int>(u * kBins)];
    }
    // The mean of n uniforms has standard deviation 1 / sqrt(12 n); allow 5 of them.
    EXPECT_NEAR(sum / kDraws, 0.5, 5.0 / std::sqrt(12.0 * kDraws));
    // Each bin count is binomial(n, 1/20): standard deviation sqrt(n p (1 - p)); allow 5.
    const double expected = double(kDraws) / kBins;
    const double sigma = std::sqrt(kDraws * (1.0 / kBins) * (1.0 - 1.0 / kBins));
    for (int count : bins) EXPECT_NEAR(count, expected, 5.0 * sigma);
}

TEST(PixelRandom, DependsOnlyOnSeedAndPixel) {
    SampleRandom a = pixel_random(7, 10, 20);
    SampleRandom b = pixel_random(7, 10, 20);
    for (int i = 0; i < 16; ++i) EXPECT_EQ(a.next_bits(), b.next_bits());
    // Neighbouring pixels, swapped coordinates and other seeds start differently.
    std::set<std::uint64_t> firsts;
    for (auto [seed, x, y] : std::vector<std::array<int, 3>>{
             {7, 10, 20}, {7, 11, 20}, {7, 10, 21}, {7, 20, 10}, {8, 10, 20}, {0, 0, 0}}) {
        firsts.insert(pixel_random(seed, x, y).next_bits());
    }
    EXPECT_EQ(firsts.size(), 6u);
}

TEST(StrataFor, FactorsTheSampleCountIntoTheSquarestGrid) {
    auto grid = [](int n) {
        const StrataGrid g = strata_for(n);
        return std::pair(g.columns, g.rows);
    };
    EXPECT_EQ(grid(1), std::pair(1, 1));
    EXPECT_EQ(grid(4), std::pair(2, 2));
    EXPECT_EQ(grid(9), std::pair(3, 3));
    EXPECT_EQ(grid(4096), std::pair(64, 64));
    EXPECT_EQ(grid(8), std::pair(4, 2));
    EXPECT_EQ(grid(12), std::pair(4, 3));
    EXPECT_EQ(grid(7), std::pair(7, 1));
    EXPECT_EQ(grid(2), std::pair(2, 1));
    EXPECT_THROW(strata_for(0), InvalidParameter);
    EXPECT_THROW(strata_for(-4), InvalidParameter);
}

TEST(StratifiedSample, PutsExactlyOneSampleInEachStratum) {
    for (int n : {1, 2, 4, 7, 8, 9, 16, 64}) {
        const StrataGrid grid = strata_for(n);
        for (int pixel = 0; pixel < 50; ++pixel) {
            SampleRandom random = pixel_random(3, pixel, 0);
            std::set<std::pair<int, int>> strata;
            for (int k = 0; k < n; ++k) {
                const Vector2 s = stratified_sample(grid, k, random);
                ASSERT_GE(s.x(), 0.0);
                ASSERT_LT(s.x(), 1.0);
                ASSERT_GE(s.y(), 0.0);
                ASSERT_LT(s.y(), 1.0);
                const int column = static_cast<int>(std::floor(s.x() * grid.columns));
                const int row = static_cast<int>(std::floor(s.y() * grid.rows));
                EXPECT_EQ(column, k % grid.columns);
                EXPECT_EQ(row, k / grid.columns);
                strata.insert({column, row});
            }
            EXPECT_EQ(static_cast<int>(strata.size()), n);
        }
    }
}

TEST(StratifiedSample, JittersWithinTheStratum) {
    // Over many pixels, the offsets within stratum 0 of a 2 x 2 grid spread over the whole
    // stratum rather than sitting at its centre.
    const StrataGrid grid = strata_for(4);
    double low = 1.0, high = 0.0;
    for (int pixel = 0; pixel < 1000; ++pixel) {
        SampleRandom random = pixel_random(1, pixel, pixel);
        const Vector2 s = stratified_sample(grid, 0, random);
        low = std::min(low, s.x());
        high = std::max(high, s.x());
    }
    EXPECT_LT(low, 0.01);
    EXPECT_GT(high, 0.49);
    EXPECT_LT(high, 0.5);
}

}  // namespace
}  // namespace csgrt
