#include "csgrt/core/torus.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/polynomial.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using Long = long double;
using LongVector = Eigen::Matrix<long double, 3, 1>;

const Torus kTorus(2.0, 0.5);

std::vector<double> all_roots(const Torus& torus, const Ray& ray) {
    double roots[4];
    const int count = torus.line_roots(ray, roots);
    return std::vector<double>(roots, roots + count);
}

TEST(Torus, RayAlongXThroughTheCentreHitsAtRPlusMinusr) {
    // From x = -5 along +x: the tube is crossed at x = -R - r, -R + r, R - r, R + r.
    const Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};
    const std::vector<double> roots = all_roots(kTorus, ray);
    ASSERT_EQ(roots.size(), 4u);
    const double expected[4] = {2.5, 3.5, 6.5, 7.5};
    // Each root is polished on the tube function: a few ulps of t.
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(roots[i], expected[i], 4 * kUnitRoundoff * 8);
    const std::optional<Hit> hit = kTorus.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 2.5, 4 * kUnitRoundoff * 8);
    EXPECT_TRUE(hit->point.isApprox(Point3(-2.5, 0, 0)));
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(-1, 0, 0)));
    EXPECT_TRUE(hit->front_face);
    const SpanList spans = kTorus.spans(ray);
    ASSERT_EQ(spans.size(), 2u);
    EXPECT_NEAR(spans[0].enter.t, 2.5, 1e-14);
    EXPECT_NEAR(spans[0].exit.t, 3.5, 1e-14);
    EXPECT_NEAR(spans[1].enter.t, 6.5, 1e-14);
    EXPECT_NEAR(spans[1].exit.t, 7.5, 1e-14);
}

TEST(Torus, NonUnitDirectionScalesT) {
    const Ray ray{Point3(-5, 0, 0), Vector3(4, 0, 0)};
    const std::optional<Hit> hit = kTorus.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 2.5 / 4, 1e-15);
}

TEST(Torus, RayAlongTheAxisThroughTheHoleMisses) {
    for (const Ray& ray :
         {Ray{Point3(0, -5, 0), Vector3(0, 1, 0)}, Ray{Point3(0, 5, 0), Vector3(0, -3, 0)},
          Ray{Point3(1.4, -5, 0), Vector3(0, 1, 0)}}) {  // hole edge at 1.5
        EXPECT_FALSE(kTorus.intersect(ray));
        EXPECT_FALSE(kTorus.occluded(ray));
        EXPECT_TRUE(kTorus.spans(ray).empty());
    }
}

TEST(Torus, ParallelToTheAxisThroughTheTube) {
    // x = R: enters the tube at y = -r and leaves at y = r.
    const std::optional<Hit> hit = kTorus.intersect(Ray{Point3(2, -5, 0), Vector3(0, 1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 4.5, 1e-14);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, -1, 0)));
}

TEST(Torus, FromInsideTheTubeHitsTheWallFromBehind) {
    // From the core circle at (R, 0, 0) along +z: leaves where sqrt(R^2 + z^2) = R + r.
    const Ray ray{Point3(2, 0, 0), Vector3(0, 0, 1)};
    const std::optional<Hit> hit = kTorus.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, std::sqrt(2.5 * 2.5 - 4.0), 1e-14);
    EXPECT_FALSE(hit->front_face);
    const SpanList spans = kTorus.spans(ray);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_NEAR(spans[0].enter.t, -std::sqrt(2.5 * 2.5 - 4.0), 1e-14);
    EXPECT_TRUE(kTorus.contains(ray.origin));
}

TEST(Torus, TangentToTheTopTouchesTwice) {
    // The plane y = r along x through the centre touches the top circle at x = -R and x = R:
    // two double roots. A tangency is reported (a zero-length span each).
    const Ray ray{Point3(-5, 0.5, 0), Vector3(1, 0, 0)};
    const std::vector<double> roots = all_roots(kTorus, ray);
    ASSERT_EQ(roots.size(), 4u);
    EXPECT_NEAR(roots[0], 3.0, 1e-12);
    EXPECT_EQ(roots[0], roots[1]);
    EXPECT_NEAR(roots[2], 7.0, 1e-12);
    EXPECT_EQ(roots[2], roots[3]);
    const std::optional<Hit> hit = kTorus.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 3.0, 1e-12);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, 1, 0), 1e-12));
    // Just above: misses; just below: crosses twice near each touching point.
    EXPECT_FALSE(kTorus.intersect(Ray{Point3(-5, 0.5 + 1e-9, 0), Vector3(1, 0, 0)}));
    const std::vector<double> below =
        all_roots(kTorus, Ray{Point3(-5, 0.5 - 1e-9, 0), Vector3(1, 0, 0)});
    ASSERT_EQ(below.size(), 4u);
    // Half-chord of a circle of radius r at depth e: sqrt(2 r e) = sqrt(1e-9) ~ 3.2e-5.
    EXPECT_NEAR(below[1] - below[0], 2 * std::sqrt(2 * 0.5 * 1e-9), 1e-9);
}

TEST(Torus, TangentToTheOuterEquatorAndTheInnerEquator) {
    // x = R + r touches the outer equator at z = 0 (outside on both sides).
    const std::vector<double> outer = all_roots(kTorus, Ray{Point3(2.5, 0, -5), Vector3(0, 0, 1)});
    ASSERT_EQ(outer.size(), 2u);
    EXPECT_NEAR(outer[0], 5.0, 1e-12);
    EXPECT_EQ(outer[0], outer[1]);
    // x = R - r runs inside the tube and touches the inner equator from inside at z = 0,
    // between entering and leaving at z = -+sqrt((R + r)^2 - (R - r)^2) = -+2 sqrt(R r).
    const Ray inner_ray{Point3(1.5, 0, -5), Vector3(0, 0, 1)};
    const std::vector<double> inner = all_roots(kTorus, inner_ray);
    ASSERT_EQ(inner.size(), 4u);
    EXPECT_NEAR(inner[0], 5.0 - 2.0, 1e-14);
    EXPECT_NEAR(inner[1], 5.0, 1e-12);
    EXPECT_EQ(inner[1], inner[2]);
    EXPECT_NEAR(inner[3], 5.0 + 2.0, 1e-14);
    const SpanList spans = kTorus.spans(inner_ray);
    ASSERT_EQ(spans.size(), 2u);
    EXPECT_EQ(spans[0].exit.t, spans[1].enter.t);  // spans touching end to start
}

TEST(Torus, GrazingTheTopCircleIsAQuadrupleRoot) {
    // y = r, z = R along x: the line lies along the top circle's tangent, where the surface is
    // flat along the circle: the quartic is x^4 (a quadruple root at x = 0, t = 5). Its
    // position is only determined to about u^(1/3) (the solver finds it as the triple root of
    // the derivative); the hit point is on the surface to rounding.
    const Ray ray{Point3(-5, 0.5, 2.0), Vector3(1, 0, 0)};
    const std::optional<Hit> hit = kTorus.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 5.0, 1e-4);
    EXPECT_FALSE(kTorus.intersect(Ray{Point3(-5, 0.5 + 1e-12, 2.0), Vector3(1, 0, 0)}));
    // Below the top plane by e the line crosses where x^4 ~ 8 R^2 r e: at |x| ~ 0.0067 for
    // e = 1e-9.
    const std::vector<double> below =
        all_roots(kTorus, Ray{Point3(-5, 0.5 - 1e-9, 2.0), Vector3(1, 0, 0)});
    ASSERT_EQ(below.size(), 2u);
    const double half = std::pow(8 * 4.0 * 0.5 * 1e-9, 0.25);
    EXPECT_NEAR(below[0], 5.0 - half, 1e-3 * half);
    EXPECT_NEAR(below[1], 5.0 + half, 1e-3 * half);
}

TEST(Torus, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};  // roots at 2.5, 3.5, 6.5, 7.5
    Ray clipped = ray;
    clipped.t_max = 2.4999;
    EXPECT_FALSE(kTorus.intersect(clipped));
    EXPECT_FALSE(kTorus.occluded(clipped));
    EXPECT_EQ(kTorus.spans(clipped).size(), 0u);
    clipped.t_max = 2.5001;
    EXPECT_TRUE(kTorus.intersect(clipped));
    clipped = ray;
    clipped.t_min = 3.0;
    ASSERT_TRUE(kTorus.intersect(clipped));
    EXPECT_NEAR(kTorus.intersect(clipped)->t, 3.5, 1e-14);
    clipped.t_min = 4.0;  // in the hole: the far side of the tube
    ASSERT_TRUE(kTorus.intersect(clipped));
    EXPECT_NEAR(kTorus.intersect(clipped)->t, 6.5, 1e-14);
    EXPECT_EQ(kTorus.spans(clipped).size(), 1u);
    clipped.t_min = 7.5001;
    EXPECT_FALSE(kTorus.intersect(clipped));
    EXPECT_FALSE(kTorus.occluded(clipped));
    clipped.t_min = 2.0;
    clipped.t_max = 2.4;  // the whole interval before the torus
    EXPECT_FALSE(kTorus.occluded(clipped));
}

TEST(Torus, InvalidRaysNeverHit) {
    const double nan = std::nan("");
    for (const Ray& ray :
         {Ray{Point3(nan, 0, -5), Vector3(0, 0, 1)}, Ray{Point3(0, 0, -5), Vector3(0, nan, 1)},
          Ray{Point3(2, 0, -5), Vector3(0, 0, 0)}, Ray{Point3(2, 0, -kInfinity), Vector3(0, 0, 1)},
          Ray{Point3(2, 0, -5), Vector3(0, 0, kInfinity)},
          Ray{Point3(2, 0, -5), Vector3(0, 0, 1), nan, kInfinity},
          Ray{Point3(2, 0, -5), Vector3(0, 0, 1), 5.0, 4.0}}) {
        EXPECT_FALSE(kTorus.intersect(ray));
        EXPECT_FALSE(kTorus.occluded(ray));
        EXPECT_TRUE(kTorus.spans(ray).empty());
    }
}

TEST(Torus, RejectsBadParameters) {
    EXPECT_THROW(Torus(0.0, 0.5), InvalidParameter);
    EXPECT_THROW(Torus(-2.0, 0.5), InvalidParameter);
    EXPECT_THROW(Torus(2.0, 0.0), InvalidParameter);
    EXPECT_THROW(Torus(2.0, -0.5), InvalidParameter);
    EXPECT_THROW(Torus(std::nan(""), 0.5), InvalidParameter);
    EXPECT_THROW(Torus(kInfinity, 0.5), InvalidParameter);
    EXPECT_THROW(Torus(2.0, std::nan("")), InvalidParameter);
    EXPECT_THROW(Torus(2.0, 2.0), InvalidParameter);  // horn torus
    EXPECT_THROW(Torus(2.0, 3.0), InvalidParameter);  // spindle torus
    try {
        Torus(1.0, 1.5);
        FAIL();
    } catch (const InvalidParameter& error) {
        EXPECT_NE(std::string(error.what()).find("Torus: minor_radius"), std::string::npos)
            << error.what();
    }
}

TEST(Torus, ContainsTheTubeOnly) {
    EXPECT_TRUE(kTorus.contains(Point3(2, 0, 0)));
    EXPECT_TRUE(kTorus.contains(Point3(0, 0.4, -2)));
    EXPECT_TRUE(kTorus.contains(Point3(2.49, 0, 0)));
    EXPECT_FALSE(kTorus.contains(Point3(2.51, 0, 0)));
    EXPECT_FALSE(kTorus.contains(Point3(0, 0, 0)));  // the hole
    EXPECT_FALSE(kTorus.contains(Point3(0, 5, 0)));
    EXPECT_FALSE(kTorus.contains(Point3(2, 0.51, 0)));
}

TEST(Torus, UvAndNormalsFollowTheParameterisation) {
    // Outer equator at +x: phi = atan2(x, z) = pi/2, theta = 0.
    const std::optional<Hit> outer = kTorus.intersect(Ray{Point3(5, 0, 0), Vector3(-1, 0, 0)});
    ASSERT_TRUE(outer);
    EXPECT_NEAR(outer->uv.x(), 0.25, 1e-12);
    EXPECT_NEAR(outer->uv.y(), 0.0, 1e-12);
    EXPECT_TRUE(outer->geometric_normal.isApprox(Normal3(1, 0, 0)));
    // Top of the tube at +z: phi = 0, theta = pi/2.
    const std::optional<Hit> top = kTorus.intersect(Ray{Point3(0, 5, 2), Vector3(0, -1, 0)});
    ASSERT_TRUE(top);
    EXPECT_NEAR(top->uv.x(), 0.0, 1e-12);
    EXPECT_NEAR(top->uv.y(), 0.25, 1e-12);
    // Inner equator at -z, seen from the hole: phi = pi, theta = pi; the normal points into
    // the hole.
    const std::optional<Hit> inner = kTorus.intersect(Ray{Point3(0, 0, 0), Vector3(0, 0, -1)});
    ASSERT_TRUE(inner);
    EXPECT_NEAR(inner->t, 1.5, 1e-14);
    EXPECT_NEAR(inner->uv.x(), 0.5, 1e-12);
    EXPECT_NEAR(inner->uv.y(), 0.5, 1e-12);
    EXPECT_TRUE(inner->geometric_normal.isApprox(Normal3(0, 0, 1)));
    // Bottom (theta = 3 pi / 2) at -x (phi = 3 pi / 2).
    const std::optional<Hit> bottom = kTorus.intersect(Ray{Point3(-2, -5, 0), Vector3(0, 1, 0)});
    ASSERT_TRUE(bottom);
    EXPECT_NEAR(bottom->uv.x(), 0.75, 1e-12);
    EXPECT_NEAR(bottom->uv.y(), 0.75, 1e-12);
}

TEST(Torus, ThinTubeAnalyticHits) {
    // r / R down to 1e-3 (and 1e-4): along x through the centre the roots are 5 -+ R -+ r;
    // polished on the tube function they keep a few ulps of t, independent of r / R.
    for (const double minor : {0.1, 1e-2, 1e-3, 1e-4}) {
        const Torus torus(1.0, minor);
        const std::vector<double> roots = all_roots(torus, Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)});
        ASSERT_EQ(roots.size(), 4u) << minor;
        const double expected[4] = {4 - minor, 4 + minor, 6 - minor, 6 + minor};
        for (int i = 0; i < 4; ++i) EXPECT_NEAR(roots[i], expected[i], 8 * kUnitRoundoff * 6);
    }
}

TEST(Torus, PropertiesOnRandomRays) {
    // Independent description: the quartic itself, evaluated in double. Its own rounding near
    // the surface is about 12 u (2 R rho)^2 (two terms of that size cancel), and its gradient
    // there has length 8 R rho r, so it reports a point on the surface as up to
    // 12 u 4 R^2 rho^2 / (8 R rho r) = 6 u R rho / r <= 6 u R (R + r) / r away. The check
    // allows distance_ulps u (|o| + |t d| + scale) with |o| + |t d| >= R - r, so distance_ulps
    // = 6 R (R + r) / (r (R - r)) + 16 (the projected hit point's own few ulps) covers it.
    for (const double minor : {0.5, 0.05}) {
        const double major = 2.0;
        const Torus torus(major, minor);
        const test::SurfaceDescription surface{
            [&](const Point3& p) {
                return square(p.squaredNorm() + major * major - minor * minor) -
                       4 * major * major * (p.x() * p.x() + p.z() * p.z());
            },
            [&](const Point3& p) {
                const double k = 4 * (p.squaredNorm() + major * major - minor * minor);
                return Vector3(k * p.x() - 8 * major * major * p.x(), k * p.y(),
                               k * p.z() - 8 * major * major * p.z());
            },
            minor, torus.bounds()};
        test::PropertyTolerance tolerance;
        tolerance.distance_ulps = 6 * major * (major + minor) / (minor * (major - minor)) + 16;
        const test::PropertyCounts counts =
            test::check_shape_properties(torus, surface, 100000, 13, tolerance);
        EXPECT_GT(counts.hits, minor > 0.1 ? 30000 : 5000);
        EXPECT_GT(counts.span_checks, 100000);
    }
}

}  // namespace
}  // namespace csgrt
