#include "csgrt/core/part_cylinder.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>  // shape_properties.h uses cross() without including it
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "csgrt/core/cylinder.h"
#include "csgrt/core/error.h"
#include "support/error_of.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

// phi = atan2(x, z): 0 on +z, pi / 2 on +x. This quarter spans from +z to +x.
const PartCylinder kQuarter(1.0, -1.0, 1.0, 0.0, kPi / 2);

TEST(PartCylinder, AnalyticHitInsideTheLimits) {
    const std::optional<Hit> hit = kQuarter.intersect(Ray{Point3(0.5, 0, 5), Vector3(0, 0, -1)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 5.0 - std::sqrt(0.75), 4 * kUnitRoundoff * 5);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0.5, 0, std::sqrt(0.75))));
    EXPECT_TRUE(hit->front_face);
    EXPECT_EQ(hit->shape, &kQuarter);
    EXPECT_NEAR(hit->uv.x(), 1.0 / 3.0, 1e-15);  // phi = pi / 6 of a pi / 2 range
    EXPECT_NEAR(hit->uv.y(), 0.5, 1e-15);
}

TEST(PartCylinder, MissesOutsideTheLimits) {
    // Both crossings at phi = 11 pi / 6 and 7 pi / 6: outside [0, pi / 2].
    EXPECT_FALSE(kQuarter.intersect(Ray{Point3(-0.5, 0, 5), Vector3(0, 0, -1)}));
    EXPECT_FALSE(kQuarter.occluded(Ray{Point3(-0.5, 0, 5), Vector3(0, 0, -1)}));
    EXPECT_FALSE(kQuarter.intersect(Ray{Point3(0.5, 1.5, 5), Vector3(0, 0, -1)}));  // above
    EXPECT_FALSE(kQuarter.intersect(Ray{Point3(0.5, 0, 5), Vector3(0, 0, 1)}));     // away
    EXPECT_FALSE(kQuarter.intersect(Ray{Point3(0.5, 5, 0.5), Vector3(0, -1, 0)}));  // parallel
    EXPECT_FALSE(kQuarter.is_solid());
    EXPECT_TRUE(kQuarter.spans(Ray{Point3(0.5, 0, 5), Vector3(0, 0, -1)}).empty());
}

TEST(PartCylinder, ThroughTheRemovedSectorOntoTheFarSide) {
    // Near crossing at phi = 5 pi / 6 (removed), far crossing at phi = pi / 6 (kept): the inside
    // of the quarter is hit from behind.
    const std::optional<Hit> hit = kQuarter.intersect(Ray{Point3(0.5, 0, -5), Vector3(0, 0, 2)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, (5.0 + std::sqrt(0.75)) / 2, 4 * kUnitRoundoff * 5);
    EXPECT_FALSE(hit->front_face);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0.5, 0, std::sqrt(0.75))));
    // Reaching the far side over the top edge: the near crossing is above y_max.
    const std::optional<Hit> over = kQuarter.intersect(Ray{Point3(0, 2, -2), Vector3(0, -1, 1.5)});
    ASSERT_TRUE(over);
    EXPECT_NEAR(over->point.z(), 1.0, 1e-15);
}

TEST(PartCylinder, SeamAtZeroAndTwoPi) {
    const Ray toward_plus_z{Point3(0, 0, 5), Vector3(0, 0, -1)};  // crosses at phi = 0 and pi
    // phi = 0 belongs to a part starting at 0, and to one ending at 2 pi.
    std::optional<Hit> hit = kQuarter.intersect(toward_plus_z);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->uv.x(), 0.0);
    const PartCylinder last_quarter(1.0, -1.0, 1.0, 3 * kPi / 2, kTwoPi);
    hit = last_quarter.intersect(toward_plus_z);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->uv.x(), 1.0);
    // A back half excludes phi = 0, so the ray goes on to phi = pi.
    const PartCylinder back(1.0, -1.0, 1.0, kPi / 2, 3 * kPi / 2);
    hit = back.intersect(toward_plus_z);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 6.0);
    EXPECT_NEAR(hit->uv.x(), 0.5, 1e-15);
    // A part across the seam, written with phi_max > 2 pi: the half around +z.
    const PartCylinder across(1.0, -1.0, 1.0, 3 * kPi / 2, 5 * kPi / 2);
    hit = across.intersect(toward_plus_z);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_NEAR(hit->uv.x(), 0.5, 1e-15);
    hit = across.intersect(Ray{Point3(-0.5, 0, 5), Vector3(0, 0, -1)});  // phi = 11 pi / 6
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->uv.x(), 1.0 / 3.0, 1e-15);
    // Crossings at 4 pi / 3 and 2 pi / 3, both in the removed back half.
    EXPECT_FALSE(across.intersect(Ray{Point3(-1.5, 0, -0.5), Vector3(1, 0, 0)}));
    // The edges 3 pi / 2 and 5 pi / 2 = pi / 2 themselves are included.
    EXPECT_EQ(across.intersect(Ray{Point3(-1.5, 0, 0), Vector3(1, 0, 0)})->t, 0.5);
    EXPECT_EQ(across.intersect(Ray{Point3(1.5, 0, 0), Vector3(-1, 0, 0)})->t, 0.5);
    // Just on the negative side of the seam: atan2 gives a tiny negative angle that rounds to
    // 2 pi, which must count as 0.
    EXPECT_EQ(AngleRange::azimuth(-1e-300, 1.0), 0.0);
    EXPECT_TRUE(kQuarter.intersect(Ray{Point3(-1e-300, 0, 5), Vector3(0, 0, -1)}));
    EXPECT_TRUE(kQuarter.azimuth().contains(kPi / 2));  // the other edge is included too
    EXPECT_TRUE(kQuarter.intersect(Ray{Point3(5, 0, 0), Vector3(-1, 0, 0)}));
}

TEST(PartCylinder, RayLyingInTheSurfaceMissesIt) {
    // 3^2 + 4^2 - 5^2 is exactly 0: the ray lies in the side at phi = atan2(3, 4), inside the
    // limits, and crosses nothing (as on an open Cylinder).
    const PartCylinder part(5.0, -1.0, 1.0, 0.0, kPi / 2);
    const Ray up{Point3(3, -10, 4), Vector3(0, 1, 0)};
    EXPECT_FALSE(part.intersect(up));
    EXPECT_FALSE(part.occluded(up));
    // Tilted inward by a hair from a point of the side within the limits, it crosses there
    // (c = 0 exactly, so the root is exactly 0) and next some 6e9 further, far above y_max.
    const Ray tilted{Point3(3, 0, 4), Vector3(-1e-9, 1, 0)};
    ASSERT_TRUE(part.intersect(tilted));
    EXPECT_EQ(part.intersect(tilted)->t, 0.0);
    EXPECT_FALSE(part.intersect(Ray{Point3(3, 0, 4), Vector3(0, 1, 0)}));
}

TEST(PartCylinder, TangentRay) {
    const Ray tangent{Point3(-5, 0, 1), Vector3(1, 0, 0)};  // touches at phi = 0
    const std::optional<Hit> hit = kQuarter.intersect(tangent);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 5.0, 1e-7);  // a double root is only determined to about sqrt(u)
    EXPECT_FALSE(PartCylinder(1.0, -1.0, 1.0, kPi / 2, 3 * kPi / 2).intersect(tangent));
}

TEST(PartCylinder, IntervalHonouredAtBothEnds) {
    // Crossings at t = 6 (z = -4, removed) and t = 14 (z = 4, phi = atan2(3, 4), kept).
    const PartCylinder part(5.0, -1.0, 1.0, 0.0, kPi / 2);
    const Ray ray{Point3(3, 0, -10), Vector3(0, 0, 1)};
    Ray clipped = ray;
    clipped.t_max = std::nextafter(14.0, 0.0);
    EXPECT_FALSE(part.intersect(clipped));
    EXPECT_FALSE(part.occluded(clipped));
    clipped.t_max = 14.0;
    ASSERT_TRUE(part.intersect(clipped));
    EXPECT_EQ(part.intersect(clipped)->t, 14.0);
    clipped = ray;
    clipped.t_min = 14.0;
    EXPECT_TRUE(part.intersect(clipped));
    clipped.t_min = std::nextafter(14.0, 15.0);
    EXPECT_FALSE(part.intersect(clipped));
    EXPECT_FALSE(part.occluded(clipped));
    const PartCylinder whole(5.0, -1.0, 1.0, 0.0, kTwoPi);
    EXPECT_EQ(whole.intersect(ray)->t, 6.0);
    clipped = ray;
    clipped.t_min = 6.0;
    EXPECT_EQ(whole.intersect(clipped)->t, 6.0);
    clipped.t_min = std::nextafter(6.0, 7.0);
    EXPECT_EQ(whole.intersect(clipped)->t, 14.0);
}

TEST(PartCylinder, InvalidRaysNeverHit) {
    test::expect_invalid_rays_miss(kQuarter, Ray{Point3(0.5, 0, 5), Vector3(0, 0, -1)});
}

void expect_rejected(double radius, double y_min, double y_max, double phi_min, double phi_max,
                     const std::string& parameter) {
    test::expect_rejected_naming([&] { PartCylinder(radius, y_min, y_max, phi_min, phi_max); },
                                 "PartCylinder", parameter);
}

TEST(PartCylinder, RejectsBadParametersNamingThem) {
    const double nan = std::nan("");
    expect_rejected(0.0, -1, 1, 0, 1, "radius");
    expect_rejected(nan, -1, 1, 0, 1, "radius");
    expect_rejected(1.0, nan, 1, 0, 1, "y_min");
    expect_rejected(1.0, -1, kInfinity, 0, 1, "y_max");
    expect_rejected(1.0, 1, 1, 0, 1, "y_max");
    expect_rejected(1.0, -1, 1, -0.1, 1, "phi_min");
    expect_rejected(1.0, -1, 1, kTwoPi, 7, "phi_min");
    expect_rejected(1.0, -1, 1, nan, 1, "phi_min");
    expect_rejected(1.0, -1, 1, 1, 1, "phi_max");
    expect_rejected(1.0, -1, 1, 1, 0.5, "phi_max");
    expect_rejected(1.0, -1, 1, 1, 1 + kTwoPi + 1e-9, "phi_max");
    expect_rejected(1.0, -1, 1, 1, nan, "phi_max");
    EXPECT_NO_THROW(PartCylinder(1.0, -1, 1, 1, 1 + kTwoPi));
}

TEST(PartCylinder, BoundsHoldOnlyTheArc) {
    const Aabb box = kQuarter.bounds();
    const double pad = 1e-14;
    EXPECT_NEAR(box.lower.x(), 0.0, pad);
    EXPECT_NEAR(box.lower.z(), 0.0, pad);
    EXPECT_NEAR(box.upper.x(), 1.0, pad);
    EXPECT_NEAR(box.upper.z(), 1.0, pad);
    EXPECT_LE(box.lower.x(), 0.0);  // padded outward: the edges at phi = 0, pi / 2 are inside
    EXPECT_GE(box.upper.x(), 1.0);
    EXPECT_EQ(box.lower.y(), -1.0);
    EXPECT_EQ(box.upper.y(), 1.0);
    const Aabb across = PartCylinder(2.0, 0.0, 1.0, 3 * kPi / 2, 5 * kPi / 2).bounds();
    EXPECT_NEAR(across.lower.x(), -2.0, pad);
    EXPECT_NEAR(across.upper.x(), 2.0, pad);
    EXPECT_NEAR(across.lower.z(), 0.0, pad);
    EXPECT_NEAR(across.upper.z(), 2.0, pad);
}

test::SurfaceDescription side_surface(const PartCylinder& part) {
    return {[&](const Point3& p) { return std::hypot(p.x(), p.z()) - part.radius(); },
            [](const Point3& p) -> Vector3 {
                return Vector3(p.x(), 0.0, p.z()) / std::hypot(p.x(), p.z());
            },
            part.radius(), part.bounds()};
}

TEST(PartCylinder, PropertiesOnRandomRays) {
    // A non-convex part (more than half the turn) and one across the seam.
    const PartCylinder wide(0.9, -0.4, 1.3, 0.3, 4.0);
    test::PropertyCounts counts =
        test::check_shape_properties(wide, side_surface(wide), 100000, 41);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 30000);
    const PartCylinder across(0.9, -0.4, 1.3, 5.5, 5.5 + 2.0);
    counts = test::check_shape_properties(across, side_surface(across), 100000, 42);
    EXPECT_GT(counts.hits, 30000);
}

// Reference: the infinite cylinder's crossings solved in long double after moving the origin
// to the line's closest approach to the axis, each kept if its height and its azimuth (atan2
// in long double) are within the limits. `margin` reports how close the accepted crossing, or
// the nearest rejected one, came to a limit (in radians or height units), so the comparison
// can skip rays that graze a limit, where one rounding decides.
long double reference_t(const PartCylinder& part, const Ray& ray, long double& margin) {
    using Real = long double;
    const Real ox = ray.origin.x(), oy = ray.origin.y(), oz = ray.origin.z();
    const Real dx = ray.direction.x(), dy = ray.direction.y(), dz = ray.direction.z();
    const Real r = part.radius();
    margin = INFINITY;
    const Real a = dx * dx + dz * dz;
    if (a == 0) return INFINITY;
    const Real shift = -(ox * dx + oz * dz) / a;
    const Real x = ox + shift * dx, z = oz + shift * dz;
    const Real discriminant = a * (r * r - (x * x + z * z));
    if (discriminant < 0) return INFINITY;
    for (Real sign : {-1.0L, 1.0L}) {
        const Real t = shift + sign * std::sqrt(discriminant) / a;
        if (t < ray.t_min) continue;
        const Real y = oy + t * dy;
        Real phi = std::atan2(ox + t * dx, oz + t * dz);
        if (phi < 0) phi += 2 * std::acos(-1.0L);
        if (phi < part.azimuth().min()) phi += 2 * std::acos(-1.0L);
        margin =
            std::min({margin, std::abs(y - part.y_min()), std::abs(y - part.y_max()),
                      std::abs(phi - part.azimuth().min()), std::abs(phi - part.azimuth().max())});
        if (y >= part.y_min() && y <= part.y_max() && phi <= part.azimuth().max()) return t;
    }
    return INFINITY;
}

// Random rays from near and far against the long double reference. The error is
// test::AlongRayError: the rounding of the coordinates (and, far away, of moving the origin)
// over the cosine between ray and normal, plus a few ulps of the cancellation-free roots.
// Bound: (16 / cos + 8) u.
void expect_matches_reference(const PartCylinder& part, double distance, std::uint64_t seed) {
    test::Random random(seed);
    int hits = 0;
    int compared = 0;
    double worst = 0.0;
    for (int i = 0; i < 50000; ++i) {
        Ray ray = random.ray_between(test::enlarged(part.bounds(), 1.0), part.bounds());
        if (distance > 0) {
            ray.origin = part.bounds().center() + random.unit_vector() * distance * part.radius();
            ray.direction = (random.in_box(part.bounds()) - ray.origin) / distance;
        }
        long double margin;
        const long double expected = reference_t(part, ray, margin);
        // Limits are judged on rounded points: skip rays within 1e-9 (far: 1e-6) of one.
        if (margin < (distance > 0 ? 1e-6 : 1e-9)) continue;
        ++compared;
        const std::optional<Hit> hit = part.intersect(ray);
        ASSERT_EQ(hit.has_value(), std::isfinite(expected)) << "ray " << i << " seed " << seed;
        if (!hit) continue;
        ++hits;
        const test::AlongRayError along = test::along_ray_error(ray, *hit, expected, part.radius());
        worst = std::max(worst, along.scaled());
        EXPECT_LE(along.error, along.bound()) << "ray " << i;
        // The hit honours the limits.
        EXPECT_GE(hit->point.y(), part.y_min());
        EXPECT_LE(hit->point.y(), part.y_max());
        EXPECT_TRUE(part.azimuth().contains(AngleRange::azimuth(hit->point.x(), hit->point.z())));
    }
    EXPECT_GT(compared, 45000);
    EXPECT_GT(hits, distance > 0 ? 10000 : 5000);
    std::printf("part cylinder from %g radii: worst error * cosine = %.2f u\n", distance, worst);
}

TEST(PartCylinder, MatchesLongDoubleReferenceNearAndFar) {
    const PartCylinder wide(0.9, -0.4, 1.3, 0.3, 4.0);
    const PartCylinder across(0.9, -0.4, 1.3, 5.5, 5.5 + 2.0);
    for (const PartCylinder* part : {&wide, &across}) {
        expect_matches_reference(*part, 0.0, 51);
        expect_matches_reference(*part, 1e3, 52);
        expect_matches_reference(*part, 1e6, 53);
    }
}

}  // namespace
}  // namespace csgrt
