#include "csgrt/core/polynomial.h"

#include <gtest/gtest.h>

#include "support/random.h"

namespace csgrt {
namespace {

TEST(SolveQuadratic, AnalyticRootsAndDegenerateCases) {
    double roots[2];
    ASSERT_EQ(solve_quadratic(1, -3, 2, roots), 2);
    EXPECT_EQ(roots[0], 1.0);
    EXPECT_EQ(roots[1], 2.0);
    EXPECT_EQ(solve_quadratic(1, 0, 1, roots), 0);
    ASSERT_EQ(solve_quadratic(1, -2, 1, roots), 2);  // double root
    EXPECT_EQ(roots[0], 1.0);
    EXPECT_EQ(roots[1], 1.0);
    ASSERT_EQ(solve_quadratic(0, 2, -4, roots), 1);  // linear
    EXPECT_EQ(roots[0], 2.0);
    EXPECT_EQ(solve_quadratic(0, 0, 1, roots), 0);
    EXPECT_EQ(solve_quadratic(std::nan(""), 1, 1, roots), 0);
}

TEST(SolveQuadratic, RootsOfVeryDifferentMagnitudeAgainstLongDouble) {
    // Roots r1, r2 spread over 1e-8 .. 1e8: the textbook formula loses the small root entirely;
    // the cancellation-free pair keeps both to a few ulps. Reference: the roots themselves,
    // exact by construction, and the coefficients rounded to double once (which perturbs the
    // roots by at most ~2 u relative times the conditioning (r1 + r2) / |r1 - r2|).
    test::Random random(31);
    for (int i = 0; i < 100000; ++i) {
        const long double r1 = std::pow(10.0L, static_cast<long double>(random.uniform(-8, 8))) *
                               (random.uniform() < 0.5 ? -1 : 1);
        const long double r2 = std::pow(10.0L, static_cast<long double>(random.uniform(-8, 8)));
        const double a = 1.0;
        const double b = static_cast<double>(-(r1 + r2));
        const double c = static_cast<double>(r1 * r2);
        double roots[2] = {0.0, 0.0};
        ASSERT_EQ(solve_quadratic(a, b, c, roots), 2) << i;
        const long double small = std::abs(r1) < std::abs(r2) ? r1 : r2;
        const long double large = std::abs(r1) < std::abs(r2) ? r2 : r1;
        const double found_small = std::abs(roots[0]) < std::abs(roots[1]) ? roots[0] : roots[1];
        const double found_large = std::abs(roots[0]) < std::abs(roots[1]) ? roots[1] : roots[0];
        const long double conditioning = std::abs(r1 + r2) / std::abs(r1 - r2) + 1;
        EXPECT_LE(std::abs((found_small - small) / small), 8 * kUnitRoundoff * conditioning) << i;
        EXPECT_LE(std::abs((found_large - large) / large), 8 * kUnitRoundoff * conditioning) << i;
    }
}

}  // namespace
}  // namespace csgrt
