#include "csgrt/core/cylinder.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>  // shape_properties.h uses cross() without including it
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "support/error_of.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

const Cylinder kOpen(1.0, -1.0, 1.0, false);
const Cylinder kCapped(1.0, -1.0, 1.0, true);

TEST(Cylinder, AnalyticHitOnTheSide) {
    for (const Cylinder* cylinder : {&kOpen, &kCapped}) {
        const std::optional<Hit> hit = cylinder->intersect(Ray{Point3(0, 0, -5), Vector3(0, 0, 2)});
        ASSERT_TRUE(hit);
        EXPECT_DOUBLE_EQ(hit->t, 2.0);
        EXPECT_TRUE(hit->point.isApprox(Point3(0, 0, -1)));
        EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, 0, -1)));
        EXPECT_TRUE(hit->front_face);
        EXPECT_EQ(hit->primitive_id, Cylinder::kSide);
        EXPECT_EQ(hit->shape, cylinder);
        EXPECT_NEAR(hit->uv.x(), 0.5, 1e-15);  // phi = atan2(0, -1) = pi
        EXPECT_NEAR(hit->uv.y(), 0.5, 1e-15);
    }
}

TEST(Cylinder, ParallelToTheAxisHitsTheCapsOfTheSolidOnly) {
    const Ray down{Point3(0.5, 5, 0), Vector3(0, -1, 0)};
    EXPECT_FALSE(kOpen.intersect(down));
    EXPECT_FALSE(kOpen.occluded(down));
    const std::optional<Hit> hit = kCapped.intersect(down);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->primitive_id, Cylinder::kTopCap);
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0));
    EXPECT_EQ(hit->point, Point3(0.5, 1, 0));
    EXPECT_TRUE(hit->front_face);
    EXPECT_NEAR(hit->uv.x(), 0.25, 1e-15);  // phi = pi / 2 at +x
    EXPECT_NEAR(hit->uv.y(), 0.5, 1e-15);   // half the radius out
    const SpanList spans = kCapped.spans(down);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 4.0);
    EXPECT_EQ(spans[0].enter.primitive, Cylinder::kTopCap);
    EXPECT_EQ(spans[0].exit.t, 6.0);
    EXPECT_EQ(spans[0].exit.primitive, Cylinder::kBottomCap);
    // Parallel but outside the radius: nothing.
    EXPECT_FALSE(kCapped.intersect(Ray{Point3(1.5, 5, 0), Vector3(0, -1, 0)}));
}

TEST(Cylinder, RayLyingInTheSide) {
    // 3^2 + 4^2 - 5^2 is exactly 0 in double: the ray lies in the side, touching it for t in
    // [9, 11]. It crosses nothing, so the open tube is missed (wherever t_min is); the solid is
    // hit at the rims, the ends of its span.
    const Cylinder open(5.0, -1.0, 1.0, false);
    const Cylinder capped(5.0, -1.0, 1.0, true);
    const Ray up{Point3(3, -10, 4), Vector3(0, 1, 0)};
    for (const double t_min : {0.0, 9.0, 10.0}) {
        Ray ray = up;
        ray.t_min = t_min;
        EXPECT_FALSE(open.intersect(ray)) << t_min;
        EXPECT_FALSE(open.occluded(ray)) << t_min;
    }
    std::optional<Hit> hit = capped.intersect(up);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 9.0);
    EXPECT_EQ(hit->primitive_id, Cylinder::kBottomCap);
    EXPECT_EQ(hit->point, Point3(3, -1, 4));
    Ray later = up;
    later.t_min = 10.0;
    hit = capped.intersect(later);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 11.0);
    EXPECT_EQ(hit->primitive_id, Cylinder::kTopCap);
    const SpanList spans = capped.spans(up);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 9.0);
    EXPECT_EQ(spans[0].exit.t, 11.0);
    // A hair inside, the solid is still hit through its caps; a hair outside, nothing is.
    const Ray inside{Point3(3, -10, std::nextafter(4.0, 0.0)), Vector3(0, 1, 0)};
    EXPECT_FALSE(open.intersect(inside));
    EXPECT_EQ(capped.intersect(inside)->t, 9.0);
    const Ray outside{Point3(3, -10, std::nextafter(4.0, 5.0)), Vector3(0, 1, 0)};
    EXPECT_FALSE(open.intersect(outside));
    EXPECT_FALSE(capped.intersect(outside));
}

TEST(Cylinder, FromInside) {
    const Ray sideways{Point3(0, 0.5, 0), Vector3(2, 0, 0)};
    for (const Cylinder* cylinder : {&kOpen, &kCapped}) {
        const std::optional<Hit> hit = cylinder->intersect(sideways);
        ASSERT_TRUE(hit);
        EXPECT_DOUBLE_EQ(hit->t, 0.5);
        EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(1, 0, 0)));
        EXPECT_FALSE(hit->front_face);
    }
    const SpanList spans = kCapped.spans(sideways);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_DOUBLE_EQ(spans[0].enter.t, -0.5);
    EXPECT_TRUE(kCapped.contains(Point3(0, 0.5, 0)));
    EXPECT_FALSE(kOpen.contains(Point3(0, 0.5, 0)));
    // Up the axis: the open tube lets it out, the solid's top cap stops it from behind.
    const Ray up{Point3(0, 0, 0), Vector3(0, 1, 0)};
    EXPECT_FALSE(kOpen.intersect(up));
    const std::optional<Hit> cap = kCapped.intersect(up);
    ASSERT_TRUE(cap);
    EXPECT_EQ(cap->t, 1.0);
    EXPECT_FALSE(cap->front_face);
}

TEST(Cylinder, ThroughTheOpenEndOntoTheInsideOfTheSide) {
    const Ray ray{Point3(0, 2, 0), Vector3(1, -2, 0)};  // reaches x = 1 at t = 1, y = 0
    const std::optional<Hit> open_hit = kOpen.intersect(ray);
    ASSERT_TRUE(open_hit);
    EXPECT_DOUBLE_EQ(open_hit->t, 1.0);
    EXPECT_FALSE(open_hit->front_face);
    const std::optional<Hit> capped_hit = kCapped.intersect(ray);
    ASSERT_TRUE(capped_hit);
    EXPECT_DOUBLE_EQ(capped_hit->t, 0.5);  // the top cap at y = 1, x = 0.5
    EXPECT_EQ(capped_hit->primitive_id, Cylinder::kTopCap);
}

TEST(Cylinder, Misses) {
    for (const Cylinder* cylinder : {&kOpen, &kCapped}) {
        EXPECT_FALSE(cylinder->intersect(Ray{Point3(1.5, 0, -5), Vector3(0, 0, 1)}));
        EXPECT_FALSE(cylinder->intersect(Ray{Point3(0, 0, -5), Vector3(0, 0, -1)}));  // away
        EXPECT_FALSE(cylinder->intersect(Ray{Point3(0, 3, -5), Vector3(0, 0, 1)}));   // above
        EXPECT_FALSE(cylinder->occluded(Ray{Point3(0, -3, -5), Vector3(0, 0, 1)}));   // below
        EXPECT_TRUE(cylinder->spans(Ray{Point3(0, 3, -5), Vector3(0, 0, 1)}).empty());
    }
}

TEST(Cylinder, TangentRayTouchesOnce) {
    const Ray tangent{Point3(-5, 0, 1), Vector3(1, 0, 0)};
    for (const Cylinder* cylinder : {&kOpen, &kCapped}) {
        const std::optional<Hit> hit = cylinder->intersect(tangent);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->t, 5.0, 1e-7);  // a double root is only determined to about sqrt(u)
    }
    const SpanList spans = kCapped.spans(tangent);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_NEAR(spans[0].enter.t, spans[0].exit.t, 1e-7);
    EXPECT_FALSE(kOpen.intersect(Ray{Point3(-5, 0, 1 + 1e-6), Vector3(1, 0, 0)}));
}

TEST(Cylinder, RayInACapPlaneGrazesTheSolid) {
    // In the plane y = 1 the closed solid is touched along a chord of the top disk: the first
    // point of contact is on the rim. The open tube is hit at its top edge, which it includes.
    const Ray grazing{Point3(-5, 1, 0), Vector3(1, 0, 0)};
    for (const Cylinder* cylinder : {&kOpen, &kCapped}) {
        const std::optional<Hit> hit = cylinder->intersect(grazing);
        ASSERT_TRUE(hit);
        EXPECT_DOUBLE_EQ(hit->t, 4.0);
        EXPECT_EQ(hit->primitive_id, Cylinder::kSide);
    }
    const SpanList spans = kCapped.spans(grazing);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_DOUBLE_EQ(spans[0].exit.t, 6.0);
    const Ray above{Point3(-5, std::nextafter(1.0, 2.0), 0), Vector3(1, 0, 0)};
    EXPECT_FALSE(kOpen.intersect(above));
    EXPECT_FALSE(kCapped.intersect(above));
}

TEST(Cylinder, IntervalHonouredAtBothEnds) {
    // Side roots at 4 and 6 (open and capped); cap roots at 4 and 6 (capped only).
    const Ray side{Point3(0, 0, -5), Vector3(0, 0, 1)};
    const Ray caps{Point3(0.5, 5, 0), Vector3(0, -1, 0)};
    std::vector<std::pair<const Cylinder*, Ray>> cases = {
        {&kOpen, side}, {&kCapped, side}, {&kCapped, caps}};
    for (const auto& [cylinder, ray] : cases) {
        Ray clipped = ray;
        clipped.t_max = std::nextafter(4.0, 0.0);
        EXPECT_FALSE(cylinder->intersect(clipped));
        EXPECT_FALSE(cylinder->occluded(clipped));
        clipped.t_max = 4.0;
        ASSERT_TRUE(cylinder->intersect(clipped));
        EXPECT_EQ(cylinder->intersect(clipped)->t, 4.0);
        clipped = ray;
        clipped.t_min = 4.5;
        ASSERT_TRUE(cylinder->intersect(clipped));
        EXPECT_EQ(cylinder->intersect(clipped)->t, 6.0);
        clipped.t_min = 6.0;
        EXPECT_TRUE(cylinder->intersect(clipped));
        clipped.t_min = std::nextafter(6.0, 7.0);
        EXPECT_FALSE(cylinder->intersect(clipped));
        EXPECT_FALSE(cylinder->occluded(clipped));
    }
    // Spans are not clipped to the interval, but one outside it is left out.
    Ray beyond = caps;
    beyond.t_min = 7.0;
    EXPECT_TRUE(kCapped.spans(beyond).empty());
    beyond.t_min = 5.0;
    ASSERT_EQ(kCapped.spans(beyond).size(), 1u);
    EXPECT_EQ(kCapped.spans(beyond)[0].enter.t, 4.0);
}

TEST(Cylinder, InvalidRaysNeverHit) {
    for (const Cylinder* cylinder : {&kOpen, &kCapped}) {
        test::expect_invalid_rays_miss(*cylinder, Ray{Point3(0, 0, -5), Vector3(0, 0, 1)});
    }
}

void expect_rejected(double radius, double y_min, double y_max, const std::string& parameter) {
    test::expect_rejected_naming([&] { Cylinder(radius, y_min, y_max, true); }, "Cylinder",
                                 parameter);
}

TEST(Cylinder, RejectsBadParametersNamingThem) {
    const double nan = std::nan("");
    expect_rejected(0.0, -1, 1, "radius");
    expect_rejected(-1.0, -1, 1, "radius");
    expect_rejected(nan, -1, 1, "radius");
    expect_rejected(kInfinity, -1, 1, "radius");
    expect_rejected(1.0, nan, 1, "y_min");
    expect_rejected(1.0, -kInfinity, 1, "y_min");
    expect_rejected(1.0, -1, kInfinity, "y_max");
    expect_rejected(1.0, 1, 1, "y_max");
    expect_rejected(1.0, 2, 1, "y_max");
    EXPECT_NO_THROW(Cylinder(1e-300, -1e300, 1e300, false));
}

TEST(Cylinder, PlacedByAnInstance) {
    // Rotating y onto x: the axis now runs along x, the top cap faces +x.
    const auto instance = std::make_shared<Instance>(std::make_shared<Cylinder>(kCapped),
                                                     Transform::rotate(Vector3(0, 0, 1), -kPi / 2));
    std::optional<Hit> hit = instance->intersect(Ray{Point3(0.5, 0, 5), Vector3(0, 0, -1)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 4.0, 1e-14);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, 0, 1), 1e-14));
    hit = instance->intersect(Ray{Point3(5, 0.5, 0), Vector3(-1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 4.0, 1e-14);
    EXPECT_EQ(hit->primitive_id, Cylinder::kTopCap);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(1, 0, 0), 1e-14));
}

// The implicit descriptions the property checks compare against: the signed distance to the
// infinite side, and for the solid the max of that and the two cap planes, which is zero
// exactly on the closed surface; the gradient is the active term's (unit) normal.
test::SurfaceDescription open_surface(const Cylinder& cylinder) {
    return {[&](const Point3& p) { return std::hypot(p.x(), p.z()) - cylinder.radius(); },
            [](const Point3& p) -> Vector3 {
                return Vector3(p.x(), 0.0, p.z()) / std::hypot(p.x(), p.z());
            },
            cylinder.radius(), cylinder.bounds()};
}

test::SurfaceDescription solid_surface(const Cylinder& cylinder) {
    auto terms = [&](const Point3& p) {
        return Vector3(std::hypot(p.x(), p.z()) - cylinder.radius(), p.y() - cylinder.y_max(),
                       cylinder.y_min() - p.y());
    };
    return {[terms](const Point3& p) {
                const Vector3 values = terms(p);
                return values.maxCoeff();
            },
            [terms](const Point3& p) -> Vector3 {
                const Vector3 values = terms(p);
                Eigen::Index active;
                values.maxCoeff(&active);
                if (active == 1) return Vector3(0, 1, 0);
                if (active == 2) return Vector3(0, -1, 0);
                return Vector3(p.x(), 0.0, p.z()) / std::hypot(p.x(), p.z());
            },
            std::max(cylinder.radius(), 0.5 * (cylinder.y_max() - cylinder.y_min())),
            cylinder.bounds()};
}

TEST(Cylinder, OpenPropertiesOnRandomRays) {
    const Cylinder cylinder(0.8, -0.7, 1.9, false);
    const test::PropertyCounts counts =
        test::check_shape_properties(cylinder, open_surface(cylinder), 100000, 21);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 30000);
}

TEST(Cylinder, CappedPropertiesOnRandomRays) {
    const Cylinder cylinder(0.8, -0.7, 1.9, true);
    const test::PropertyCounts counts =
        test::check_shape_properties(cylinder, solid_surface(cylinder), 100000, 22);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 30000);
    EXPECT_GT(counts.span_checks, 100000);
}

// Reference: the same surfaces solved in long double (64-bit significand), from the ray's own
// double origin and direction. The line is first moved to its closest approach to the axis in
// long double, so the reference's own error is about 2^-64 |o| in position, 2^11 below the
// double computation's.
long double reference_t(const Cylinder& cylinder, const Ray& ray) {
    using Real = long double;
    const Real ox = ray.origin.x(), oy = ray.origin.y(), oz = ray.origin.z();
    const Real dx = ray.direction.x(), dy = ray.direction.y(), dz = ray.direction.z();
    const Real r = cylinder.radius();
    Real best = INFINITY;
    auto consider = [&](Real t) {
        if (t >= ray.t_min && t < best) best = t;
    };
    const Real a = dx * dx + dz * dz;
    if (a > 0) {
        const Real shift = -(ox * dx + oz * dz) / a;
        const Real x = ox + shift * dx, z = oz + shift * dz;
        const Real discriminant = a * (r * r - (x * x + z * z));  // b = 0 at closest approach
        if (discriminant >= 0) {
            for (Real sign : {-1.0L, 1.0L}) {
                const Real t = shift + sign * std::sqrt(discriminant) / a;
                const Real y = oy + t * dy;
                if (y >= cylinder.y_min() && y <= cylinder.y_max()) consider(t);
            }
        }
    }
    if (cylinder.capped() && dy != 0) {
        for (Real plane : {Real(cylinder.y_min()), Real(cylinder.y_max())}) {
            const Real t = (plane - oy) / dy;
            const Real x = ox + t * dx, z = oz + t * dz;
            if (x * x + z * z <= r * r) consider(t);
        }
    }
    return best;
}

// Rays from origins `distance` radii away in random directions, aimed at random points of the
// side (and caps) away from the rims. The error is test::AlongRayError (a distance along the
// ray relative to the magnitudes involved), at most (16 / cos + 8) u.
void expect_accurate_from_afar(const Cylinder& cylinder, double distance, std::uint64_t seed) {
    test::Random random(seed);
    const Point3 center(0.0, 0.5 * (cylinder.y_min() + cylinder.y_max()), 0.0);
    double worst = 0.0;
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const double phi = random.uniform(0.0, kTwoPi);
        Point3 target;
        const int surface = cylinder.capped() ? random.integer(0, 2) : 0;
        if (surface == 0) {
            const double height = cylinder.y_max() - cylinder.y_min();
            target = Point3(cylinder.radius() * std::sin(phi),
                            cylinder.y_min() + height * random.uniform(0.05, 0.95),
                            cylinder.radius() * std::cos(phi));
        } else {
            const double rho = cylinder.radius() * std::sqrt(random.uniform(0.0, 0.9));
            target = Point3(rho * std::sin(phi), surface == 1 ? cylinder.y_min() : cylinder.y_max(),
                            rho * std::cos(phi));
        }
        const Point3 origin = center + random.unit_vector() * distance * cylinder.radius();
        const Ray ray{origin, (target - origin) * random.uniform(0.25, 4.0) / distance};
        const long double expected = reference_t(cylinder, ray);
        const std::optional<Hit> hit = cylinder.intersect(ray);
        ASSERT_EQ(hit.has_value(), std::isfinite(expected)) << "ray " << i;
        if (!hit) continue;
        ++hits;
        const test::AlongRayError along =
            test::along_ray_error(ray, *hit, expected, cylinder.radius());
        worst = std::max(worst, along.scaled());
        EXPECT_LE(along.error, along.bound())
            << "ray " << i << " at " << distance << " radii, cosine " << along.cosine;
    }
    EXPECT_GT(hits, 15000);
    std::printf("cylinder (%s) from %g radii: worst error * cosine = %.2f u\n",
                cylinder.capped() ? "capped" : "open", distance, worst);
}

TEST(Cylinder, AccurateFromFarAway) {
    for (const bool capped : {false, true}) {
        const Cylinder cylinder(0.5, -0.25, 1.5, capped);
        expect_accurate_from_afar(cylinder, 1e3, 31);
        expect_accurate_from_afar(cylinder, 1e6, 32);
    }
}

}  // namespace
}  // namespace csgrt
