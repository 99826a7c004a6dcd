#include "csgrt/core/cone.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>  // shape_properties.h uses cross() without including it
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "csgrt/core/cylinder.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "support/error_of.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

// rho(y) = 1 - y / 2: apex (0, 2, 0); the cut-away nappe is y > 2 with radius y / 2 - 1.
const Cone kOpen(1.0, 0.0, 2.0, false);
const Cone kCapped(1.0, 0.0, 2.0, true);
// cos and sin of the half angle: the side normal is (cos * radial, sin, ...) for slope -1/2.
const double kRadial = 2.0 / std::sqrt(5.0);
const double kUp = 1.0 / std::sqrt(5.0);

TEST(Cone, AnalyticHitOnTheSide) {
    for (const Cone* cone : {&kOpen, &kCapped}) {
        const std::optional<Hit> hit = cone->intersect(Ray{Point3(0, 1, -5), Vector3(0, 0, 1)});
        ASSERT_TRUE(hit);
        EXPECT_EQ(hit->t, 4.5);  // rho(1) = 0.5
        EXPECT_TRUE(hit->point.isApprox(Point3(0, 1, -0.5)));
        EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, kUp, -kRadial), 1e-15));
        EXPECT_NEAR(hit->geometric_normal.norm(), 1.0, 4 * kUnitRoundoff);
        EXPECT_TRUE(hit->front_face);
        EXPECT_EQ(hit->primitive_id, Cone::kSide);
        EXPECT_NEAR(hit->uv.x(), 0.5, 1e-15);  // phi = atan2(0, -0.5) = pi
        EXPECT_NEAR(hit->uv.y(), 0.5, 1e-15);
    }
}

TEST(Cone, BaseCapAndInsideOfTheSide) {
    const Ray up{Point3(0.5, -5, 0), Vector3(0, 1, 0)};  // base at t = 5, side (rho = 0.5) at 6
    const std::optional<Hit> cap = kCapped.intersect(up);
    ASSERT_TRUE(cap);
    EXPECT_EQ(cap->t, 5.0);
    EXPECT_EQ(cap->primitive_id, Cone::kBaseCap);
    EXPECT_EQ(cap->geometric_normal, Normal3(0, -1, 0));
    EXPECT_TRUE(cap->front_face);
    EXPECT_NEAR(cap->uv.y(), 0.5, 1e-15);
    const SpanList spans = kCapped.spans(up);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 5.0);
    EXPECT_NEAR(spans[0].exit.t, 6.0, 4 * kUnitRoundoff * 6);
    EXPECT_EQ(spans[0].exit.primitive, Cone::kSide);
    // Open: no base, so the ray enters freely and meets the side from inside.
    const std::optional<Hit> side = kOpen.intersect(up);
    ASSERT_TRUE(side);
    EXPECT_NEAR(side->t, 6.0, 4 * kUnitRoundoff * 6);
    EXPECT_FALSE(side->front_face);
    EXPECT_TRUE(side->geometric_normal.isApprox(Normal3(kRadial, kUp, 0), 1e-15));
    // A frustum's top cap.
    const Cone frustum(2.0, 1.0, 2.0, true);
    const std::optional<Hit> top = frustum.intersect(Ray{Point3(0.5, 5, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(top);
    EXPECT_EQ(top->t, 3.0);
    EXPECT_EQ(top->primitive_id, Cone::kTopCap);
    EXPECT_EQ(top->geometric_normal, Normal3(0, 1, 0));
    EXPECT_FALSE(Cone(2.0, 1.0, 2.0, false).intersect(Ray{Point3(0.5, 5, 0), Vector3(0, -1, 0)}));
}

TEST(Cone, TheOtherNappeIsNeverReported) {
    // Crosses the cut-away nappe at x = -0.5 and 0.5 (y = 3) and nothing else.
    const Ray above{Point3(-5, 3, 0), Vector3(1, 0, 0)};
    // Starts inside the cut-away nappe, leaves it at y = 7/3 (t = 5/3), meets ours at y = 1.5.
    const Ray through{Point3(0, 4, 0), Vector3(0.1, -1, 0)};
    for (const Cone* cone : {&kOpen, &kCapped}) {
        EXPECT_FALSE(cone->intersect(above));
        EXPECT_FALSE(cone->occluded(above));
        EXPECT_TRUE(cone->spans(above).empty());
        const std::optional<Hit> hit = cone->intersect(through);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->t, 2.5, 1e-14);
        EXPECT_NEAR(hit->point.y(), 1.5, 1e-14);
    }
    // Likewise for an apex at the base: the cut-away nappe is below y = 0.
    const Cone inverted(0.0, 1.0, 1.0, true);
    EXPECT_FALSE(inverted.intersect(Ray{Point3(-5, -1, 0), Vector3(1, 0, 0)}));
    EXPECT_FALSE(Cone(0.0, 1.0, 1.0, false).intersect(Ray{Point3(-5, -1, 0), Vector3(1, 0, 0)}));
}

TEST(Cone, RayDownTheAxisHitsTheApex) {
    const Ray down{Point3(0, 5, 0), Vector3(0, -1, 0)};
    for (const Cone* cone : {&kOpen, &kCapped}) {
        const std::optional<Hit> hit = cone->intersect(down);
        ASSERT_TRUE(hit);
        EXPECT_EQ(hit->t, 3.0);
        EXPECT_EQ(hit->primitive_id, Cone::kApex);
        EXPECT_EQ(hit->point, Point3(0, 2, 0));
        EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0));
        EXPECT_TRUE(hit->front_face);
        EXPECT_EQ(hit->uv, Vector2(0, 1));
    }
    const SpanList spans = kCapped.spans(down);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 3.0);
    EXPECT_EQ(spans[0].enter.primitive, Cone::kApex);
    EXPECT_EQ(spans[0].exit.t, 5.0);
    EXPECT_EQ(spans[0].exit.primitive, Cone::kBaseCap);
    // Past the apex the open cone has nothing left to hit; the solid has its base.
    Ray past = down;
    past.t_min = 3.5;
    EXPECT_FALSE(kOpen.intersect(past));
    EXPECT_EQ(kCapped.intersect(past)->t, 5.0);
    // From inside, up the axis: the apex from behind.
    const std::optional<Hit> inside = kOpen.intersect(Ray{Point3(0, 0.5, 0), Vector3(0, 2, 0)});
    ASSERT_TRUE(inside);
    EXPECT_EQ(inside->t, 0.75);
    EXPECT_EQ(inside->primitive_id, Cone::kApex);
    EXPECT_FALSE(inside->front_face);
    // Starting at the apex.
    for (const Cone* cone : {&kOpen, &kCapped}) {
        const std::optional<Hit> at = cone->intersect(Ray{Point3(0, 2, 0), Vector3(1, 1, 0)});
        ASSERT_TRUE(at);
        EXPECT_EQ(at->t, 0.0);
        EXPECT_EQ(at->primitive_id, Cone::kApex);
    }
}

TEST(Cone, RayTouchingOnlyTheApex) {
    // Shallower than the side: the solid is touched at the apex alone, a zero-length span.
    const std::pair<Ray, double> cases[] = {{Ray{Point3(-5, 2, 0), Vector3(1, 0, 0)}, 5.0},
                                            {Ray{Point3(-3, 3, -4), Vector3(3, -1, 4)}, 1.0}};
    for (const auto& [ray, t] : cases) {
        for (const Cone* cone : {&kOpen, &kCapped}) {
            const std::optional<Hit> hit = cone->intersect(ray);
            ASSERT_TRUE(hit);
            EXPECT_EQ(hit->t, t);
            EXPECT_EQ(hit->primitive_id, Cone::kApex);
            EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0));
        }
        const SpanList spans = kCapped.spans(ray);
        ASSERT_EQ(spans.size(), 1u);
        EXPECT_EQ(spans[0].enter.t, t);
        EXPECT_EQ(spans[0].exit.t, t);
    }
    // A hair above the apex: a clean miss.
    EXPECT_FALSE(kCapped.intersect(Ray{Point3(-5, 2 + 1e-9, 0), Vector3(1, 0, 0)}));
}

TEST(Cone, RaysAimedAtTheApexFromEverywhereHitIt) {
    test::Random random(61);
    const Cone inverted(0.0, 1.5, 1.0, true);
    for (const Cone* cone : {&kOpen, &kCapped, &inverted}) {
        const Point3 apex = cone->apex();
        const Normal3 tip = cone->apex().y() > 0 ? Normal3(0, 1, 0) : Normal3(0, -1, 0);
        int tip_side = 0;
        for (int i = 0; i < 20000; ++i) {
            const double distance = std::pow(10.0, random.uniform(-3, 6));
            const Point3 origin = apex + random.unit_vector() * distance;
            const Ray ray{origin, (apex - origin) * random.uniform(0.25, 4.0)};
            const std::optional<Hit> hit = cone->intersect(ray);
            ASSERT_TRUE(hit) << "ray " << i;
            ASSERT_TRUE(cone->occluded(ray)) << "ray " << i;
            EXPECT_TRUE(is_finite(hit->geometric_normal));
            EXPECT_NEAR(hit->geometric_normal.norm(), 1.0, 4 * kUnitRoundoff);
            const double t_apex = (apex - origin).dot(ray.direction) / ray.direction.squaredNorm();
            EXPECT_LE(hit->t, t_apex * (1 + 1e-12)) << "ray " << i;
            // From the tip's side of the apex plane nothing of the cone comes first.
            if ((origin - apex).dot(tip) > 0) {
                ++tip_side;
                EXPECT_EQ(hit->primitive_id, Cone::kApex) << "ray " << i;
                EXPECT_EQ(hit->geometric_normal, tip);
                EXPECT_EQ(hit->point, apex);
            }
        }
        EXPECT_GT(tip_side, 8000);
    }
}

TEST(Cone, RayAlongAGenerator) {
    // rho(y) = 1 - y: the generator from (1, 0, 0) to the apex (0, 1, 0), t in [1, 2]. The ray
    // crosses nothing, but passes the apex, which the open cone reports; the solid's span runs
    // from the rim to the apex.
    const Cone open(1.0, 0.0, 1.0, false);
    const Cone capped(1.0, 0.0, 1.0, true);
    const Ray along{Point3(2, -1, 0), Vector3(-1, 1, 0)};
    std::optional<Hit> hit = open.intersect(along);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 2.0);
    EXPECT_EQ(hit->primitive_id, Cone::kApex);
    Ray later = along;
    later.t_min = 2.5;
    EXPECT_FALSE(open.intersect(later));
    hit = capped.intersect(along);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 1.0);
    EXPECT_EQ(hit->primitive_id, Cone::kBaseCap);  // the rim
    later.t_min = 1.5;
    EXPECT_EQ(capped.intersect(later)->t, 2.0);
    EXPECT_EQ(capped.intersect(later)->primitive_id, Cone::kApex);
    // A frustum has no apex: its open side is missed, its solid hit at both rims.
    const Ray along_frustum{Point3(3, -1, 0), Vector3(-1, 1, 0)};  // rho(y) = 2 - y
    EXPECT_FALSE(Cone(2.0, 1.0, 1.0, false).intersect(along_frustum));
    const SpanList spans = Cone(2.0, 1.0, 1.0, true).spans(along_frustum);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 1.0);
    EXPECT_EQ(spans[0].enter.primitive, Cone::kBaseCap);
    EXPECT_EQ(spans[0].exit.t, 2.0);
    EXPECT_EQ(spans[0].exit.primitive, Cone::kTopCap);
}

TEST(Cone, TangentToTheSide) {
    // Touches the side at (0.5, 1, 0), perpendicular to the radius there.
    const Ray tangent{Point3(0.5, 1, -5), Vector3(0, 0, 1)};
    for (const Cone* cone : {&kOpen, &kCapped}) {
        const std::optional<Hit> hit = cone->intersect(tangent);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(hit->t, 5.0, 1e-7);  // a double root is only determined to about sqrt(u)
    }
    EXPECT_FALSE(kCapped.intersect(Ray{Point3(0.5 + 1e-6, 1, -5), Vector3(0, 0, 1)}));
}

TEST(Cone, ParallelToTheAxis) {
    const Cone frustum_open(2.0, 1.0, 2.0, false);
    const Cone frustum_capped(2.0, 1.0, 2.0, true);
    const Ray down_inside{Point3(0.5, 5, 0), Vector3(0, -1, 0)};
    EXPECT_FALSE(frustum_open.intersect(down_inside));  // in through the top, out the bottom
    EXPECT_EQ(frustum_capped.intersect(down_inside)->t, 3.0);
    const SpanList spans = frustum_capped.spans(down_inside);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].exit.t, 5.0);
    // Outside the top circle but inside the base: the open side is hit where rho = 1.5.
    const Ray down_between{Point3(1.5, 5, 0), Vector3(0, -1, 0)};
    EXPECT_NEAR(frustum_open.intersect(down_between)->t, 4.0, 1e-14);
    EXPECT_NEAR(frustum_capped.intersect(down_between)->t, 4.0, 1e-14);
    EXPECT_FALSE(frustum_capped.intersect(Ray{Point3(2.5, 5, 0), Vector3(0, -1, 0)}));
    // Equal radii make a cylinder, and vertical rays then never cross the side.
    const Cone tube(1.0, 1.0, 2.0, false);
    EXPECT_FALSE(tube.intersect(Ray{Point3(0.5, 5, 0), Vector3(0, -1, 0)}));
    EXPECT_EQ(Cone(1.0, 1.0, 2.0, true).intersect(Ray{Point3(0.5, 5, 0), Vector3(0, -1, 0)})->t,
              3.0);
    // ... not even lying in it (3, 4, 5: exactly on the side in double).
    EXPECT_FALSE(Cone(5.0, 5.0, 2.0, false).intersect(Ray{Point3(3, 5, 4), Vector3(0, -1, 0)}));
    EXPECT_EQ(Cone(5.0, 5.0, 2.0, true).intersect(Ray{Point3(3, 5, 4), Vector3(0, -1, 0)})->t, 3.0);
}

TEST(Cone, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(0, 1, -5), Vector3(0, 0, 1)};      // side at 4.5 and 5.5
    const Ray caps{Point3(0.25, -5, 0), Vector3(0, 1, 0)};  // base at 5, side at 6.5
    std::vector<std::tuple<const Cone*, Ray, double, double>> cases = {
        {&kOpen, ray, 4.5, 5.5}, {&kCapped, ray, 4.5, 5.5}, {&kCapped, caps, 5.0, 6.5}};
    for (const auto& [cone, base, first, second] : cases) {
        Ray clipped = base;
        clipped.t_max = std::nextafter(first, 0.0);
        EXPECT_FALSE(cone->intersect(clipped));
        EXPECT_FALSE(cone->occluded(clipped));
        clipped.t_max = first;
        ASSERT_TRUE(cone->intersect(clipped));
        EXPECT_EQ(cone->intersect(clipped)->t, first);
        clipped = base;
        clipped.t_min = std::nextafter(first, second);
        ASSERT_TRUE(cone->intersect(clipped));
        EXPECT_EQ(cone->intersect(clipped)->t, second);
        clipped.t_min = second;
        EXPECT_TRUE(cone->intersect(clipped));
        clipped.t_min = std::nextafter(second, 10.0);
        EXPECT_FALSE(cone->intersect(clipped));
        EXPECT_FALSE(cone->occluded(clipped));
    }
}

TEST(Cone, InvalidRaysNeverHit) {
    const double nan = std::nan("");
    for (const Ray& ray :
         {Ray{Point3(nan, 1, -5), Vector3(0, 0, 1)}, Ray{Point3(0, 1, -5), Vector3(0, nan, 1)},
          Ray{Point3(0, 1, -5), Vector3(0, 0, 0)}, Ray{Point3(0, 1, -kInfinity), Vector3(0, 0, 1)},
          Ray{Point3(0, 5, 0), Vector3(0, -kInfinity, 0)},
          Ray{Point3(0, 1, -5), Vector3(0, 0, 1), nan, kInfinity},
          Ray{Point3(0, 1, -5), Vector3(0, 0, 1), 5.0, 4.0}}) {
        for (const Cone* cone : {&kOpen, &kCapped}) {
            EXPECT_FALSE(cone->intersect(ray));
            EXPECT_FALSE(cone->occluded(ray));
            EXPECT_TRUE(cone->spans(ray).empty());
        }
    }
}

void expect_rejected(double base, double top, double height, const std::string& parameter) {
    test::expect_rejected_naming([&] { Cone(base, top, height, true); }, "Cone", parameter);
}

TEST(Cone, RejectsBadParametersNamingThem) {
    const double nan = std::nan("");
    expect_rejected(-1, 0, 1, "base_radius");
    expect_rejected(nan, 0, 1, "base_radius");
    expect_rejected(kInfinity, 0, 1, "base_radius");
    expect_rejected(1, -1, 1, "top_radius");
    expect_rejected(1, nan, 1, "top_radius");
    expect_rejected(0, 0, 1, "top_radius");
    expect_rejected(1, 0, 0, "height");
    expect_rejected(1, 0, -1, "height");
    expect_rejected(1, 0, nan, "height");
    expect_rejected(1, 0, kInfinity, "height");
    EXPECT_NO_THROW(Cone(0, 1, 1, false));
    EXPECT_NO_THROW(Cone(1, 1, 1, false));
}

TEST(Cone, PlacedByAnInstance) {
    // Tip down, moved to (0, 10, 0): the apex lands at (0, 8, 0) and points along -y.
    const auto instance = std::make_shared<Instance>(
        std::make_shared<Cone>(kCapped),
        Transform::translate(Vector3(0, 10, 0)) * Transform::rotate(Vector3(1, 0, 0), kPi));
    const std::optional<Hit> hit = instance->intersect(Ray{Point3(0, 0, 0), Vector3(0, 1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 8.0, 1e-14);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, -1, 0), 1e-14));
    EXPECT_TRUE(hit->front_face);
}

TEST(Cone, CylinderLikeConeAgreesWithCylinder) {
    // Equal radii: the cone's general quadratic against the Cylinder's own code.
    const Cone cone(0.7, 0.7, 1.5, true);
    const Cylinder cylinder(0.7, 0.0, 1.5, true);
    test::Random random(62);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Ray ray = random.ray_between(test::enlarged(cone.bounds(), 1.0), cone.bounds());
        const std::optional<Hit> a = cone.intersect(ray);
        const std::optional<Hit> b = cylinder.intersect(ray);
        ASSERT_EQ(a.has_value(), b.has_value()) << "ray " << i;
        if (!a) continue;
        ++hits;
        EXPECT_NEAR(a->t, b->t, 64 * kUnitRoundoff * (a->t + 4)) << "ray " << i;
        EXPECT_EQ(a->primitive_id, b->primitive_id) << "ray " << i;  // side, bottom, top agree
    }
    EXPECT_GT(hits, 5000);
}

// The implicit descriptions: the signed distance to the infinite cone, (|xz| - rho(y)) cos of
// the half angle, which is positive on the cut-away nappe (rho < 0), so a hit there fails; for
// the solid, the max of that and the two cap planes, zero exactly on the closed surface.
double side_distance(const Cone& cone, const Point3& p) {
    const double slope = (cone.top_radius() - cone.base_radius()) / cone.height();
    return (std::hypot(p.x(), p.z()) - cone.radius_at(p.y())) / std::sqrt(1 + slope * slope);
}

Vector3 side_gradient(const Cone& cone, const Point3& p) {
    const double slope = (cone.top_radius() - cone.base_radius()) / cone.height();
    const double distance = std::hypot(p.x(), p.z());
    return Vector3(p.x() / distance, -slope, p.z() / distance) / std::sqrt(1 + slope * slope);
}

test::SurfaceDescription surface_of(const Cone& cone) {
    const double scale = std::max({cone.base_radius(), cone.top_radius(), 0.5 * cone.height()});
    if (!cone.capped()) {
        return {[&](const Point3& p) { return side_distance(cone, p); },
                [&](const Point3& p) { return side_gradient(cone, p); }, scale, cone.bounds()};
    }
    auto terms = [&](const Point3& p) {
        return Vector3(side_distance(cone, p), p.y() - cone.height(), -p.y());
    };
    return {[terms](const Point3& p) {
                const Vector3 values = terms(p);
                return values.maxCoeff();
            },
            [terms, &cone](const Point3& p) -> Vector3 {
                const Vector3 values = terms(p);
                Eigen::Index active;
                values.maxCoeff(&active);
                if (active == 1) return Vector3(0, 1, 0);
                if (active == 2) return Vector3(0, -1, 0);
                return side_gradient(cone, p);
            },
            scale, cone.bounds()};
}

TEST(Cone, PropertiesOnRandomRays) {
    // Pointed up, pointed down (apex at the base), and a frustum widening upward.
    const Cone cones[] = {Cone(0.9, 0.0, 1.7, false), Cone(0.9, 0.0, 1.7, true),
                          Cone(0.0, 1.2, 0.8, false), Cone(0.0, 1.2, 0.8, true),
                          Cone(0.4, 1.1, 1.3, false), Cone(0.4, 1.1, 1.3, true)};
    std::uint64_t seed = 70;
    for (const Cone& cone : cones) {
        const test::PropertyCounts counts =
            test::check_shape_properties(cone, surface_of(cone), 100000, ++seed);
        EXPECT_EQ(counts.rays, 100000);
        EXPECT_GT(counts.hits, 25000) << "seed " << seed;
        if (cone.capped()) {
            EXPECT_GT(counts.span_checks, 100000) << "seed " << seed;
        }
    }
}

// Reference: the cone solved in long double (64-bit significand) from the ray's own double
// origin and direction, after moving the origin in long double to the line's closest approach
// to the cone's center, with the textbook quadratic; side roots kept for y in [0, height] (our
// nappe), caps where x^2 + z^2 <= cap radius^2.
long double reference_t(const Cone& cone, const Ray& ray) {
    using Real = long double;
    const Real dx = ray.direction.x(), dy = ray.direction.y(), dz = ray.direction.z();
    const Real h = cone.height();
    const Real shift = ((0 - Real(ray.origin.x())) * dx + (h / 2 - Real(ray.origin.y())) * dy +
                        (0 - Real(ray.origin.z())) * dz) /
                       (dx * dx + dy * dy + dz * dz);
    const Real ox = ray.origin.x() + shift * dx, oy = ray.origin.y() + shift * dy,
               oz = ray.origin.z() + shift * dz;
    const Real slope = (Real(cone.top_radius()) - cone.base_radius()) / h;
    Real best = INFINITY;
    auto consider = [&](Real t) {
        if (t + shift >= ray.t_min && t + shift < best) best = t + shift;
    };
    const Real w = cone.base_radius() + slope * oy, rate = slope * dy;
    const Real a = dx * dx + dz * dz - rate * rate;
    const Real b = ox * dx + oz * dz - w * rate;
    const Real c = ox * ox + oz * oz - w * w;
    const Real discriminant = b * b - a * c;
    if (a != 0 && discriminant >= 0) {
        for (Real sign : {-1.0L, 1.0L}) {
            const Real t = (-b + sign * std::sqrt(discriminant)) / a;
            const Real y = oy + t * dy;
            if (y >= 0 && y <= h) consider(t);
        }
    }
    if (cone.capped() && dy != 0) {
        for (const Real plane : {Real(0), h}) {
            const Real t = (plane - oy) / dy;
            const Real x = ox + t * dx, z = oz + t * dz;
            const Real radius = plane == 0 ? cone.base_radius() : cone.top_radius();
            if (x * x + z * z <= radius * radius) consider(t);
        }
    }
    return best;
}

// Rays from origins `distance` times the cone's size away, aimed at random points of the side
// and caps away from the edges and the apex. Error and bound as for every shape of revolution:
// test::AlongRayError, at most (16 / cos + 8) u.
void expect_accurate_from_afar(const Cone& cone, double distance, std::uint64_t seed) {
    test::Random random(seed);
    const double size = std::max({cone.base_radius(), cone.top_radius(), cone.height()});
    const Point3 center(0.0, 0.5 * cone.height(), 0.0);
    double worst = 0.0;
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const double phi = random.uniform(0.0, kTwoPi);
        int surface = cone.capped() ? random.integer(0, 2) : 0;
        if (surface == 2 && cone.top_radius() == 0.0) surface = 1;  // no top cap on a point
        Point3 target;
        if (surface == 0) {
            const double y = cone.height() * random.uniform(0.05, 0.95);
            target =
                Point3(cone.radius_at(y) * std::sin(phi), y, cone.radius_at(y) * std::cos(phi));
        } else {
            const double y = surface == 1 ? 0.0 : cone.height();
            const double rho = cone.radius_at(y) * std::sqrt(random.uniform(0.0, 0.9));
            target = Point3(rho * std::sin(phi), y, rho * std::cos(phi));
        }
        const Point3 origin = center + random.unit_vector() * distance * size;
        const Ray ray{origin, (target - origin) * random.uniform(0.25, 4.0) / distance};
        const long double expected = reference_t(cone, ray);
        const std::optional<Hit> hit = cone.intersect(ray);
        ASSERT_EQ(hit.has_value(), std::isfinite(expected)) << "ray " << i;
        if (!hit) continue;
        ++hits;
        const test::AlongRayError along = test::along_ray_error(ray, *hit, expected, size);
        worst = std::max(worst, along.scaled());
        EXPECT_LE(along.error, along.bound())
            << "ray " << i << " at " << distance << ", cosine " << along.cosine;
    }
    EXPECT_GT(hits, 10000);
    std::printf("cone (%g, %g, %g, %s) from %g sizes: worst error * cosine = %.2f u\n",
                cone.base_radius(), cone.top_radius(), cone.height(),
                cone.capped() ? "capped" : "open", distance, worst);
}

TEST(Cone, AccurateFromFarAway) {
    for (const bool capped : {false, true}) {
        for (const Cone& cone : {Cone(0.5, 0.0, 1.5, capped), Cone(0.3, 0.8, 0.6, capped)}) {
            expect_accurate_from_afar(cone, 1e3, 81);
            expect_accurate_from_afar(cone, 1e6, 82);
        }
    }
}

}  // namespace
}  // namespace csgrt
