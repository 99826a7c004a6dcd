#include "csgrt/core/part_torus.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "csgrt/core/error.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

constexpr double kMajor = 2.0;
constexpr double kMinor = 0.5;

// The angles of a point, computed here in long double (independently of Torus).
void angles_of(const Point3& p, long double& phi, long double& theta) {
    const long double x = p.x(), y = p.y(), z = p.z();
    phi = std::atan2(x, z);
    if (phi < 0) phi += 2 * 3.14159265358979323846264338327950288L;
    theta = std::atan2(y, std::sqrt(x * x + z * z) - kMajor);
    if (theta < 0) theta += 2 * 3.14159265358979323846264338327950288L;
}

// Whether `angle` lies in [min, max] taken modulo 2 pi, within `slack` radians.
bool in_angle_range(long double angle, double min, double max, long double slack) {
    const long double two_pi = 2 * 3.14159265358979323846264338327950288L;
    long double offset = std::fmod(angle - min, two_pi);
    if (offset < 0) offset += two_pi;
    return offset <= (max - min) + slack || offset >= two_pi - slack;
}

TEST(PartTorus, HalfAroundTheAxisSkipsTheRemovedSide) {
    // phi in [0, pi] is the side x >= 0. Along +x through the centre the torus is crossed at
    // x = -2.5, -1.5 (removed) and 1.5, 2.5 (kept): the first kept crossing is at t = 6.5.
    const PartTorus part(kMajor, kMinor, 0.0, kPi, 0.0, kTwoPi);
    const std::optional<Hit> hit = part.intersect(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 6.5, 1e-14);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(-1, 0, 0)));  // the inner wall
    EXPECT_TRUE(hit->front_face);
    EXPECT_EQ(hit->shape, &part);
    // From the other side the kept half is met first.
    const std::optional<Hit> back = part.intersect(Ray{Point3(5, 0, 0), Vector3(-1, 0, 0)});
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->t, 2.5, 1e-14);
}

TEST(PartTorus, OuterHalfOfTheTubeSeenFromTheHole) {
    // theta in [3 pi/2, 5 pi/2] keeps the outer half (rho >= R). From the centre along +x the
    // inner wall (theta = pi) at x = 1.5 is removed; the outer wall at x = 2.5 is hit from
    // inside, so the ray meets its back.
    const PartTorus part(kMajor, kMinor, 0.0, kTwoPi, 3 * kPi / 2, 5 * kPi / 2);
    const std::optional<Hit> hit = part.intersect(Ray{Point3(0, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 2.5, 1e-14);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(1, 0, 0)));
    EXPECT_FALSE(hit->front_face);
    EXPECT_NEAR(hit->uv.y(), 0.5, 1e-12);  // theta = 0 = 2 pi is the middle of the range
}

TEST(PartTorus, PhiSeamAtZeroEqualsTwoPi) {
    // Straight down onto the top of the tube at +z: phi = atan2(0, 2) = 0 exactly.
    const Ray top{Point3(0, 5, 2), Vector3(0, -1, 0)};
    EXPECT_TRUE(PartTorus(kMajor, kMinor, 0.0, kPi, 0, kTwoPi).intersect(top));
    EXPECT_TRUE(PartTorus(kMajor, kMinor, kPi, kTwoPi, 0, kTwoPi).intersect(top));
    EXPECT_FALSE(PartTorus(kMajor, kMinor, kPi / 2, 3 * kPi / 2, 0, kTwoPi).intersect(top));
    // A range across the seam, [7 pi/4, 9 pi/4], keeps both sides of phi = 0 ...
    const PartTorus across(kMajor, kMinor, 7 * kPi / 4, 9 * kPi / 4, 0, kTwoPi);
    for (const double x : {-0.3, -1e-9, 0.0, 1e-9, 0.3}) {
        const std::optional<Hit> hit = across.intersect(Ray{Point3(x, 5, 2), Vector3(0, -1, 0)});
        ASSERT_TRUE(hit) << x;
        // ... and its u runs from 0 at 7 pi/4 to 1 at 9 pi/4 through 0.5 at the seam.
        EXPECT_NEAR(hit->uv.x(), 0.5 + std::atan2(x, 2.0) / (kPi / 2), 1e-9) << x;
    }
    // ... and nothing beyond: phi = atan2(1.9, 0.6) ~ 1.27 > pi/4.
    EXPECT_FALSE(across.intersect(Ray{Point3(1.9, 5, 0.6), Vector3(0, -1, 0)}));
}

TEST(PartTorus, ThetaSeamAtZeroEqualsTwoPi) {
    // Along -x in the plane y = 0 onto the outer equator: theta = atan2(0, 0.5) = 0 exactly.
    const Ray equator{Point3(5, 0, 0), Vector3(-1, 0, 0)};
    EXPECT_TRUE(PartTorus(kMajor, kMinor, 0, kTwoPi, 0.0, kPi / 2).intersect(equator));
    EXPECT_TRUE(PartTorus(kMajor, kMinor, 0, kTwoPi, 3 * kPi / 2, kTwoPi).intersect(equator));
    // [pi/2, 3 pi/2] is the inner half: the outer equator is skipped, the inner wall at
    // x = 1.5 (t = 3.5) is the first kept crossing.
    const std::optional<Hit> inner =
        PartTorus(kMajor, kMinor, 0, kTwoPi, kPi / 2, 3 * kPi / 2).intersect(equator);
    ASSERT_TRUE(inner);
    EXPECT_NEAR(inner->t, 3.5, 1e-14);
    // The band [7 pi/4, 9 pi/4] around the outer equator keeps points just above and below.
    const PartTorus band(kMajor, kMinor, 0, kTwoPi, 7 * kPi / 4, 9 * kPi / 4);
    for (const double y : {-0.3, -1e-9, 0.0, 1e-9, 0.3}) {
        const std::optional<Hit> hit = band.intersect(Ray{Point3(5, y, 0), Vector3(-1, 0, 0)});
        ASSERT_TRUE(hit) << y;
        EXPECT_NEAR(hit->uv.y(), 0.5 + std::asin(y / kMinor) / (kPi / 2), 1e-9) << y;
    }
    // At y = 0.45 every crossing has theta = asin(0.9) or pi - asin(0.9): all removed.
    EXPECT_FALSE(band.intersect(Ray{Point3(5, 0.45, 0), Vector3(-1, 0, 0)}));
    EXPECT_FALSE(band.occluded(Ray{Point3(5, 0.45, 0), Vector3(-1, 0, 0)}));
}

TEST(PartTorus, FullRangesAreTheWholeSurface) {
    const PartTorus whole(kMajor, kMinor, 0, kTwoPi, 0, kTwoPi);
    const Torus torus(kMajor, kMinor);
    test::Random random(401);
    int hits = 0;
    for (int i = 0; i < 10000; ++i) {
        const Ray ray = random.ray_between(test::enlarged(torus.bounds(), 1.0), torus.bounds());
        const std::optional<Hit> expected = torus.intersect(ray);
        const std::optional<Hit> hit = whole.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected.has_value()) << i;
        if (!hit) continue;
        ++hits;
        EXPECT_EQ(hit->t, expected->t);
        EXPECT_EQ(hit->geometric_normal, expected->geometric_normal);
        EXPECT_NEAR(hit->uv.x(), expected->uv.x(), 1e-12);
        EXPECT_NEAR(hit->uv.y(), expected->uv.y(), 1e-12);
    }
    EXPECT_GT(hits, 3000);
}

TEST(PartTorus, EveryHitIsTheFirstTorusCrossingInRange) {
    // Random ranges (some across the seams) and random rays, against an independent choice:
    // the torus's crossings in [t_min, t_max], the first whose angles (computed in long double
    // here) lie in both ranges. Crossings within 1e-9 rad of a range end may go either way.
    test::Random random(402);
    const Torus torus(kMajor, kMinor);
    int hits = 0;
    int skips = 0;
    for (int shape = 0; shape < 100; ++shape) {
        const double phi_min = random.uniform(0, kTwoPi);
        const double phi_max = phi_min + random.uniform(0.1, kTwoPi);
        const double theta_min = random.uniform(0, kTwoPi);
        const double theta_max = theta_min + random.uniform(0.1, kTwoPi);
        const PartTorus part(kMajor, kMinor, phi_min, phi_max, theta_min, theta_max);
        for (int i = 0; i < 1000; ++i) {
            Ray ray = random.ray_between(test::enlarged(torus.bounds(), 1.0), torus.bounds());
            if (i % 3 == 0) ray.t_min = random.uniform(0, 2);
            double roots[4];
            const int count = torus.line_roots(ray, roots);
            int expected = -1;
            bool ambiguous = false;
            for (int k = 0; k < count && expected < 0; ++k) {
                if (!ray.in_range(roots[k])) continue;
                long double phi, theta;
                angles_of(ray.at(roots[k]), phi, theta);
                const bool inside = in_angle_range(phi, phi_min, phi_max, -1e-9L) &&
                                    in_angle_range(theta, theta_min, theta_max, -1e-9L);
                const bool near = in_angle_range(phi, phi_min, phi_max, 1e-9L) &&
                                  in_angle_range(theta, theta_min, theta_max, 1e-9L);
                if (inside != near) ambiguous = true;
                if (inside) expected = k;
            }
            if (ambiguous) {
                ++skips;
                continue;
            }
            const std::optional<Hit> hit = part.intersect(ray);
            ASSERT_EQ(hit.has_value(), expected >= 0) << "shape " << shape << " ray " << i;
            EXPECT_EQ(part.occluded(ray), hit.has_value());
            if (!hit) continue;
            ++hits;
            EXPECT_EQ(hit->t, roots[expected]);
            long double phi, theta;
            angles_of(hit->point, phi, theta);
            EXPECT_TRUE(in_angle_range(phi, phi_min, phi_max, 1e-9L)) << phi;
            EXPECT_TRUE(in_angle_range(theta, theta_min, theta_max, 1e-9L)) << theta;
            EXPECT_GE(hit->uv.x(), 0.0);
            EXPECT_LE(hit->uv.x(), 1.0);
            EXPECT_GE(hit->uv.y(), 0.0);
            EXPECT_LE(hit->uv.y(), 1.0);
        }
    }
    EXPECT_GT(hits, 20000);
    EXPECT_LT(skips, 100);
}

TEST(PartTorus, BoundsHoldThePartAndOnlyIt) {
    // Half around the axis (x >= 0), upper outer quarter of the tube (rho >= R, y >= 0).
    const PartTorus half(kMajor, kMinor, 0.0, kPi, 0.0, kPi / 2);
    const double pad = 32 * kUnitRoundoff * (kMajor + kMinor);
    EXPECT_NEAR(half.bounds().lower.x(), 0.0, pad);
    EXPECT_NEAR(half.bounds().upper.x(), kMajor + kMinor, pad);
    EXPECT_NEAR(half.bounds().lower.y(), 0.0, pad);
    EXPECT_NEAR(half.bounds().upper.y(), kMinor, pad);
    EXPECT_NEAR(half.bounds().lower.z(), -(kMajor + kMinor), pad);
    // Against sampled points of random parts (some across the seams): every point inside.
    test::Random random(404);
    for (int shape = 0; shape < 200; ++shape) {
        const double phi_min = random.uniform(0, kTwoPi);
        const double phi_width = random.uniform(0.01, kTwoPi);
        const double theta_min = random.uniform(0, kTwoPi);
        const double theta_width = random.uniform(0.01, kTwoPi);
        const PartTorus part(kMajor, kMinor, phi_min, phi_min + phi_width, theta_min,
                             theta_min + theta_width);
        EXPECT_TRUE(Torus(kMajor, kMinor).bounds().contains(part.bounds().center()));
        for (int i = 0; i <= 200; ++i) {
            // The corners and edges of the angle rectangle, and random points inside it.
            const double phi = phi_min + phi_width * (i < 100 ? (i % 10) / 9.0 : random.uniform());
            const double theta =
                theta_min + theta_width * (i < 100 ? (i / 10) / 9.0 : random.uniform());
            const double rho = kMajor + kMinor * std::cos(theta);
            const Point3 p(rho * std::sin(phi), kMinor * std::sin(theta), rho * std::cos(phi));
            ASSERT_TRUE(part.bounds().contains(p)) << "shape " << shape << " point " << i;
        }
    }
}

TEST(PartTorus, IntervalHonouredAtBothEnds) {
    const PartTorus part(kMajor, kMinor, 0.0, kPi, 0.0, kTwoPi);  // kept: t = 6.5 and 7.5
    Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};
    ray.t_max = 6.4999;
    EXPECT_FALSE(part.intersect(ray));
    EXPECT_FALSE(part.occluded(ray));
    ray.t_max = 6.5001;
    EXPECT_TRUE(part.intersect(ray));
    ray.t_max = kInfinity;
    ray.t_min = 7.0;
    ASSERT_TRUE(part.intersect(ray));
    EXPECT_NEAR(part.intersect(ray)->t, 7.5, 1e-14);
    ray.t_min = 7.5001;
    EXPECT_FALSE(part.intersect(ray));
    EXPECT_FALSE(part.occluded(ray));
}

TEST(PartTorus, IsAnOpenSurface) {
    const PartTorus part(kMajor, kMinor, 0.0, kPi, 0.0, kTwoPi);
    EXPECT_FALSE(part.is_solid());
    EXPECT_FALSE(part.contains(Point3(2, 0, 0)));
    EXPECT_TRUE(part.spans(Ray{Point3(5, 0, 0), Vector3(-1, 0, 0)}).empty());
    EXPECT_EQ(part.kind(), "part_torus");
}

TEST(PartTorus, InvalidRaysNeverHit) {
    const PartTorus part(kMajor, kMinor, 0.0, kPi, 0.0, kTwoPi);
    const double nan = std::nan("");
    test::expect_misses(
        part, {Ray{Point3(nan, 0, 0), Vector3(-1, 0, 0)}, Ray{Point3(5, 0, 0), Vector3(0, 0, 0)},
               Ray{Point3(5, 0, 0), Vector3(-1, kInfinity, 0)},
               Ray{Point3(5, 0, 0), Vector3(-1, 0, 0), 3.0, 2.0}});
}

TEST(PartTorus, RejectsBadParameters) {
    EXPECT_THROW(PartTorus(0.0, 0.5, 0, 1, 0, 1), InvalidParameter);
    EXPECT_THROW(PartTorus(2.0, 2.5, 0, 1, 0, 1), InvalidParameter);
    EXPECT_THROW(PartTorus(2.0, -0.5, 0, 1, 0, 1), InvalidParameter);
    EXPECT_THROW(PartTorus(2.0, 0.5, 1, 1, 0, 1), InvalidParameter);      // empty phi range
    EXPECT_THROW(PartTorus(2.0, 0.5, 1, 0, 0, 1), InvalidParameter);      // reversed
    EXPECT_THROW(PartTorus(2.0, 0.5, 0, 7, 0, 1), InvalidParameter);      // wider than 2 pi
    EXPECT_THROW(PartTorus(2.0, 0.5, 0, 1, 0.5, 0.5), InvalidParameter);  // empty theta range
    EXPECT_THROW(PartTorus(2.0, 0.5, std::nan(""), 1, 0, 1), InvalidParameter);
    EXPECT_THROW(PartTorus(2.0, 0.5, 0, 1, 0, kInfinity), InvalidParameter);
    try {
        PartTorus(2.0, 3.0, 0, 1, 0, 1);
        FAIL();
    } catch (const InvalidParameter& error) {
        EXPECT_NE(std::string(error.what()).find("PartTorus: minor_radius"), std::string::npos)
            << error.what();
    }
    // The ranges follow AngleRange's rules: min in [0, 2 pi), so no negative start.
    EXPECT_THROW(PartTorus(2.0, 0.5, -0.1, 1, 0, 1), InvalidParameter);
    EXPECT_THROW(PartTorus(2.0, 0.5, kTwoPi, 7, 0, 1), InvalidParameter);
    try {
        PartTorus(2.0, 0.5, 0, 1, -0.5, 0.5);
        FAIL();
    } catch (const InvalidParameter& error) {
        EXPECT_NE(std::string(error.what()).find("PartTorus: theta_min"), std::string::npos)
            << error.what();
    }
    EXPECT_NO_THROW(PartTorus(2.0, 0.5, kPi, 3 * kPi, 0, kTwoPi));  // full ranges
}

TEST(PartTorus, PropertiesOnRandomRays) {
    // The whole torus's quartic as the independent surface.
    const PartTorus part(kMajor, kMinor, 0.3, 4.0, 5.0, 8.5);
    const test::PropertyCounts counts =
        test::check_shape_properties(part, test::torus_surface(kMajor, kMinor, part.bounds()),
                                     100000, 403, test::torus_tolerance(kMajor, kMinor));
    EXPECT_GT(counts.hits, 20000);
}

}  // namespace
}  // namespace csgrt
