#include "csgrt/bench/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/random.h"

namespace csgrt::bench {
namespace {

TEST(Quantiles, NearestRankOnKnownSample) {
    // 1..100 shuffled: the nearest-rank median is the 50th value, the 99th percentile the 99th.
    std::vector<double> values;
    for (int i = 100; i >= 1; --i) values.push_back(i);
    const Quantiles q = quantiles(values);
    EXPECT_EQ(q.median, 50.0);
    EXPECT_EQ(q.p99, 99.0);
    EXPECT_EQ(q.max, 100.0);
    // Ten values: rank ceil(0.99 * 10) = 10 is the maximum.
    const Quantiles small = quantiles({3, 1, 2, 5, 4, 9, 8, 7, 6, 10});
    EXPECT_EQ(small.median, 5.0);
    EXPECT_EQ(small.p99, 10.0);
}

TEST(Quantiles, EmptySampleAndNaN) {
    const Quantiles empty = quantiles({});
    EXPECT_EQ(empty.median, 0.0);
    EXPECT_EQ(empty.max, 0.0);
    // A NaN sorts last, so it shows up as the maximum instead of corrupting the order.
    const Quantiles with_nan = quantiles({1.0, std::nan(""), 2.0, 3.0});
    EXPECT_EQ(with_nan.median, 2.0);
    EXPECT_TRUE(std::isnan(with_nan.max));
}

TEST(PowerFit, RecoversAnExactPowerLaw) {
    std::vector<double> n, time;
    for (double size = 1e3; size <= 1e7; size *= 4) {
        n.push_back(size);
        time.push_back(3.0 * std::pow(size, 1.5));
    }
    const PowerFit fit = fit_power_law(n, time);
    ASSERT_TRUE(fit.valid);
    // Logs of values up to ~1e11 are exact to ~1e-15 relative; the sums keep that.
    EXPECT_NEAR(fit.exponent, 1.5, 1e-12);
    EXPECT_NEAR(fit.coefficient, 3.0, 3.0 * 1e-10);
    EXPECT_NEAR(fit.r_squared, 1.0, 1e-12);
}

TEST(PowerFit, NoisyLogarithmicGrowthHasASmallExponent) {
    // time = log2(n) * (1 +- 10%): without noise the least-squares slope of log(log n)
    // against log n is about (ln ln 1e7 - ln ln 1e3) / ln 1e4 = 0.092 for n spread over
    // 10^3..10^7 (the local slope 1 / ln n falls from 0.14 to 0.06). The noise adds at most
    // 0.1 to each log time; the slope's standard deviation is then about
    // 0.058 / sqrt(30 * ln(1e4)^2 / 12) = 0.004, so 0.02 is five of them.
    test::Random random(7);
    std::vector<double> n, time, exact;
    for (int i = 0; i < 30; ++i) {
        const double size = std::pow(10.0, random.uniform(3.0, 7.0));
        n.push_back(size);
        exact.push_back(std::log2(size));
        time.push_back(std::log2(size) * random.uniform(0.9, 1.1));
    }
    const PowerFit noiseless = fit_power_law(n, exact);
    ASSERT_TRUE(noiseless.valid);
    EXPECT_NEAR(noiseless.exponent, 0.092, 0.015);
    const PowerFit fit = fit_power_law(n, time);
    ASSERT_TRUE(fit.valid);
    EXPECT_NEAR(fit.exponent, noiseless.exponent, 0.02);
}

TEST(PowerFit, SkipsUnusablePointsAndNeedsTwoSizes) {
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<double> n = {10, 100, 1000, -5, 0, 10000};
    const std::vector<double> time = {10, 100, 1000, 7, 3, std::nan("")};
    const PowerFit fit = fit_power_law(n, time);
    ASSERT_TRUE(fit.valid);
    EXPECT_NEAR(fit.exponent, 1.0, 1e-12);
    EXPECT_FALSE(fit_power_law(std::vector<double>{10}, std::vector<double>{5}).valid);
    EXPECT_FALSE(fit_power_law(std::vector<double>{10, 10}, std::vector<double>{5, 6}).valid);
    EXPECT_FALSE(fit_power_law(std::vector<double>{10, inf}, std::vector<double>{5, 6}).valid);
}

TEST(ParetoFront, DominatedPointsAreOff) {
    const std::vector<CostError> points = {
        {1.0, 0.5},   // fastest: on
        {2.0, 0.1},   // on
        {3.0, 0.1},   // slower and no more accurate than the previous: off
        {2.5, 0.3},   // dominated by (2, 0.1): off
        {5.0, 0.0},   // most accurate: on
        {5.0, 0.0},   // the same point again: both on
        {0.5, 1.0}};  // fastest of all: on
    const std::vector<bool> front = pareto_front(points);
    EXPECT_EQ(front, (std::vector<bool>{true, true, false, false, true, true, true}));
}

}  // namespace
}  // namespace csgrt::bench
