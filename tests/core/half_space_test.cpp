#include "csgrt/core/half_space.h"

#include <gtest/gtest.h>

#include <cmath>

#include "csgrt/core/error.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/boolean.h"
#include "support/leaf_checks.h"
#include "support/random.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using LongVector = Eigen::Matrix<long double, 3, 1>;

LongVector to_long(const Vector3& v) { return v.cast<long double>(); }

// The solid below the plane y = 1 (its normal, +y, points away from the solid).
const HalfSpace kBelow(Point3(0, 1, 0), Normal3(0, 3, 0));

TEST(HalfSpace, SpansFromAboveAndBelowEndAtInfinity) {
    // Down from y = 5: outside until the plane at t = 2, inside to +infinity.
    SpanList spans = kBelow.spans(Ray{Point3(0.5, 5, -2), Vector3(0, -2, 0)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 2.0);
    EXPECT_EQ(spans[0].enter.shape, &kBelow);
    EXPECT_EQ(spans[0].exit.t, kInfinity);
    EXPECT_EQ(spans[0].exit.shape, nullptr);
    // Up from y = -3: inside from -infinity until the plane at t = 4.
    spans = kBelow.spans(Ray{Point3(0, -3, 0), Vector3(0, 1, 0)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, -kInfinity);
    EXPECT_EQ(spans[0].enter.shape, nullptr);
    EXPECT_EQ(spans[0].exit.t, 4.0);
    // Up from above: the only span ends behind the origin.
    EXPECT_TRUE(kBelow.spans(Ray{Point3(0, 5, 0), Vector3(0.3, 1, 0)}).empty());
    EXPECT_FALSE(kBelow.intersect(Ray{Point3(0, 5, 0), Vector3(0.3, 1, 0)}));
}

TEST(HalfSpace, ParallelRaysAreWhollyInsideOrOutside) {
    SpanList spans = kBelow.spans(Ray{Point3(0, 0.5, 0), Vector3(1, 0, 2)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, -kInfinity);
    EXPECT_EQ(spans[0].exit.t, kInfinity);
    EXPECT_EQ(spans[0].enter.shape, nullptr);
    EXPECT_EQ(spans[0].exit.shape, nullptr);
    EXPECT_TRUE(kBelow.spans(Ray{Point3(0, 1.5, 0), Vector3(1, 0, 2)}).empty());
    EXPECT_FALSE(kBelow.intersect(Ray{Point3(0, 0.5, 0), Vector3(1, 0, 0)}));
}

TEST(HalfSpace, TheNormalPointsOutOfTheSolid) {
    // Arriving from inside: back-facing.
    const std::optional<Hit> hit = test::expect_hit_from_behind(
        kBelow, Ray{Point3(0, -3, 0), Vector3(0, 1, 0)}, 4.0, Normal3(0, 1, 0));
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->shape, &kBelow);
    EXPECT_TRUE(kBelow.contains(Point3(3, 0.999, -7)));
    EXPECT_FALSE(kBelow.contains(Point3(3, 1.001, -7)));
}

TEST(HalfSpace, ObliqueCrossingsAgreeWithTheClosedFormInLongDouble) {
    const Point3 point(0.3, -1.2, 2.5);
    const Normal3 normal(1, 2, -0.5);
    const HalfSpace half(point, normal);
    const LongVector unit = to_long(normal).normalized();
    test::Random random(21);
    const Aabb region(point - Vector3::Constant(4), point + Vector3::Constant(4));
    int crossings = 0;
    for (int i = 0; i < 2000; ++i) {
        const Ray ray = random.ray_between(test::enlarged(region, 1.0), region);
        const LongVector origin = to_long(ray.origin);
        const LongVector direction = to_long(ray.direction);
        const long double rate = direction.dot(unit);
        const long double t = (to_long(point) - origin).dot(unit) / rate;
        const SpanList spans = half.spans(ray);
        // The one boundary, and which side of it is inside, from the plane's equation.
        const bool inside_after = rate < 0;
        if (!inside_after && t < ray.t_min) {
            // Inside only before a crossing behind the origin: nothing in [t_min, t_max].
            EXPECT_TRUE(spans.empty()) << i;
            continue;
        }
        ASSERT_EQ(spans.size(), 1u) << i;
        const double crossing = inside_after ? spans[0].enter.t : spans[0].exit.t;
        // t = (p - o).n / d.n, each dot product off by a few roundings of its largest terms
        // (and n by its normalisation): |p - o| u and |t| |d| u over |d.n|, which grows as the
        // ray turns parallel to the plane.
        const long double scale =
            ((to_long(point) - origin).norm() + std::abs(t) * direction.norm()) / std::abs(rate);
        EXPECT_NEAR(crossing, static_cast<double>(t), 16 * kUnitRoundoff * scale) << i;
        EXPECT_EQ(inside_after ? spans[0].exit.t : spans[0].enter.t,
                  inside_after ? kInfinity : -kInfinity);
        ++crossings;
    }
    EXPECT_GT(crossings, 1000);
}

TEST(HalfSpace, PropertiesOfASolid) {
    const Point3 point(1, 2, 3);
    const Normal3 normal(-0.4, 1, 0.7);
    const HalfSpace half(point, normal);
    const Vector3 unit = normal.normalized();
    test::SurfaceDescription surface;
    surface.value = [=](const Point3& p) { return (p - point).dot(unit); };
    surface.gradient = [=](const Point3&) { return unit; };
    surface.scale = 2.0;
    surface.region = Aabb(point - Vector3::Constant(2), point + Vector3::Constant(2));
    const test::PropertyCounts counts = test::check_shape_properties(half, surface, 3000, 5);
    EXPECT_GT(counts.hits, 1000);
    EXPECT_GT(counts.span_checks, 4000);
}

TEST(HalfSpace, CutsASphereIntoAHemisphereWhoseHitsAreTheClosedForms) {
    // Sphere of radius 2 at the origin, intersected with y < 0.5: a cap-less lower part with a
    // flat disk of radius sqrt(4 - 0.25) on top.
    const auto sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 2.0);
    const auto below = std::make_shared<HalfSpace>(Point3(0, 0.5, 0), Normal3(0, 1, 0));
    const auto cut = make_intersection({sphere, below});
    EXPECT_EQ(cut->bounds().upper, sphere->bounds().upper);  // the sphere's box bounds it
    test::Random random(8);
    int flat = 0, round = 0;
    for (int i = 0; i < 3000; ++i) {
        const Ray ray = random.ray_between(Aabb(Point3(-6, -6, -6), Point3(6, 6, 6)),
                                           Aabb(Point3(-2, -2, -2), Point3(2, 2, 2)));
        // Closed form in long double: the sphere's roots, clipped to y <= 0.5.
        const LongVector o = to_long(ray.origin), d = to_long(ray.direction);
        const long double a = d.dot(d), b = o.dot(d), c = o.dot(o) - 4;
        const long double discriminant = b * b - a * c;
        long double expected = kInfinity;
        bool expected_flat = false;
        if (discriminant > 0) {
            long double enter = (-b - std::sqrt(discriminant)) / a;
            long double exit = (-b + std::sqrt(discriminant)) / a;
            if (d.y() != 0) {
                const long double t_plane = (0.5L - o.y()) / d.y();
                if (d.y() > 0) {
                    exit = std::min(exit, t_plane);
                } else if (t_plane > enter) {
                    enter = t_plane;
                    expected_flat = true;
                }
            } else if (o.y() >= 0.5L) {
                exit = enter - 1;
            }
            if (enter <= exit) {
                if (enter >= 0) {
                    expected = enter;
                } else if (exit >= 0) {
                    expected = exit;
                    expected_flat = d.y() > 0 && exit == (0.5L - o.y()) / d.y();
                }
            }
        }
        const std::optional<Hit> hit = cut->intersect(ray);
        ASSERT_EQ(hit.has_value(), expected < kInfinity) << i;
        if (!hit) continue;
        EXPECT_NEAR(hit->t, static_cast<double>(expected), 1e-12 * (1 + std::abs(hit->t))) << i;
        EXPECT_LE(hit->point.y(), 0.5 + 1e-12) << i;
        flat += expected_flat;
        round += !expected_flat;
        // On the surface the library names (near the rim both are right): the flat disk with
        // the plane's normal, or the sphere with the radial one.
        if (hit->shape == below.get()) {
            EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0)) << i;
            EXPECT_NEAR(hit->point.y(), 0.5, 1e-12) << i;
            EXPECT_LE(hit->point.squaredNorm(), 4 + 1e-12) << i;
        } else {
            EXPECT_NEAR(hit->point.norm(), 2.0, 1e-12) << i;
            EXPECT_NEAR(hit->geometric_normal.dot(hit->point / 2), 1.0, 1e-12) << i;
        }
        // Point membership just past the hit, against the two closed forms.
        const Point3 past = ray.at(hit->t + 1e-6);
        EXPECT_EQ(cut->contains(past), past.squaredNorm() < 4 && past.y() < 0.5) << i;
    }
    EXPECT_GT(flat, 100);
    EXPECT_GT(round, 300);
}

TEST(HalfSpace, InvalidParametersAreRefusedInItsName) {
    EXPECT_THROW(HalfSpace(Point3(0, 0, 0), Normal3(0, 0, 0)), InvalidParameter);
    EXPECT_THROW(HalfSpace(Point3(kInfinity, 0, 0), Normal3(0, 1, 0)), InvalidParameter);
    try {
        HalfSpace(Point3(0, 0, 0), Normal3(0, 0, 0));
    } catch (const InvalidParameter& error) {
        EXPECT_EQ(std::string(error.what()).rfind("HalfSpace: normal", 0), 0u) << error.what();
    }
}

}  // namespace
}  // namespace csgrt
