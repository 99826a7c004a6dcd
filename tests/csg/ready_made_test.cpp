#include "csgrt/csg/ready_made.h"

#include <gtest/gtest.h>

// shape_properties.h uses cross() but does not include the Eigen module that defines it.
#include <Eigen/Geometry>
#include <vector>

#include "csgrt/core/error.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/boolean.h"
#include "support/random.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

// An independent description of a solid as the largest of a few implicit terms, each negative
// inside its half of the solid and zero on its surface, with its gradient: the solid is where
// every term is negative, its surface where the largest is zero.
struct Term {
    std::function<double(const Point3&)> value;
    std::function<Vector3(const Point3&)> gradient;
};

struct Solid {
    std::vector<Term> terms;
    double scale;
    Aabb region;

    std::size_t active(const Point3& p) const {
        std::size_t best = 0;
        for (std::size_t i = 1; i < terms.size(); ++i) {
            if (terms[i].value(p) > terms[best].value(p)) best = i;
        }
        return best;
    }
    double value(const Point3& p) const { return terms[active(p)].value(p); }

    test::SurfaceDescription surface() const {
        return {[this](const Point3& p) { return value(p); },
                [this](const Point3& p) { return terms[active(p)].gradient(p); }, scale, region};
    }
};

// Terms of a solid of revolution about the unit axis `u` through `base`, in local coordinates
// s = (p - base) . u along the axis and rho = the distance from the axis.
double along(const Point3& p, const Point3& base, const Vector3& u) {
    return (p - base).dot(u);
}
Vector3 radial(const Point3& p, const Point3& base, const Vector3& u) {
    const Vector3 offset = p - base;
    return offset - offset.dot(u) * u;
}

Solid solid_cylinder(const Point3& bottom, const Point3& top, double radius) {
    const Vector3 u = (top - bottom).normalized();
    const double length = (top - bottom).norm();
    Solid solid{{{[=](const Point3& p) { return radial(p, bottom, u).norm() - radius; },
                  [=](const Point3& p) { return Vector3(radial(p, bottom, u).normalized()); }},
                 {[=](const Point3& p) { return -along(p, bottom, u); },
                  [=](const Point3&) { return Vector3(-u); }},
                 {[=](const Point3& p) { return along(p, bottom, u) - length; },
                  [=](const Point3&) { return u; }}},
                std::max(radius, 0.5 * length),
                Aabb(bottom, top)};
    solid.region = Aabb(solid.region.lower - Vector3::Constant(radius),
                        solid.region.upper + Vector3::Constant(radius));
    return solid;
}

Solid solid_cone(const Point3& base, const Point3& top, double base_radius, double top_radius) {
    const Vector3 u = (top - base).normalized();
    const double length = (top - base).norm();
    const double slope = (top_radius - base_radius) / length;
    Solid solid{
        {{[=](const Point3& p) {
              return radial(p, base, u).norm() - (base_radius + slope * along(p, base, u));
          },
          [=](const Point3& p) { return Vector3(radial(p, base, u).normalized() - slope * u); }},
         {[=](const Point3& p) { return -along(p, base, u); },
          [=](const Point3&) { return Vector3(-u); }},
         {[=](const Point3& p) { return along(p, base, u) - length; },
          [=](const Point3&) { return u; }}},
        std::max({base_radius, top_radius, 0.5 * length}),
        Aabb(base, top)};
    const double reach = std::max(base_radius, top_radius);
    solid.region = Aabb(solid.region.lower - Vector3::Constant(reach),
                        solid.region.upper + Vector3::Constant(reach));
    return solid;
}

double rho(const Point3& p) {
    return std::hypot(p.x(), p.z());
}
Vector3 rho_gradient(const Point3& p) {
    return Vector3(p.x(), 0, p.z()) / rho(p);
}

Solid thick_ring(double y_min, double y_max, double inner, double outer) {
    return Solid{{{[=](const Point3& p) { return rho(p) - outer; },
                   [](const Point3& p) { return rho_gradient(p); }},
                  {[=](const Point3& p) { return inner - rho(p); },
                   [](const Point3& p) { return Vector3(-rho_gradient(p)); }},
                  {[=](const Point3& p) { return p.y() - y_max; },
                   [](const Point3&) { return Vector3(0, 1, 0); }},
                  {[=](const Point3& p) { return y_min - p.y(); },
                   [](const Point3&) { return Vector3(0, -1, 0); }}},
                 outer,
                 Aabb(Point3(-outer, y_min, -outer), Point3(outer, y_max, outer))};
}

Solid bowl(double outer, double inner) {
    return Solid{
        {{[=](const Point3& p) { return p.norm() - outer; },
          [](const Point3& p) { return Vector3(p.normalized()); }},
         {[=](const Point3& p) { return inner - p.norm(); },
          [](const Point3& p) { return Vector3(-p.normalized()); }},
         {[](const Point3& p) { return p.y(); }, [](const Point3&) { return Vector3(0, 1, 0); }}},
        outer,
        Aabb(Point3(-outer, -outer, -outer), Point3(outer, 0, outer))};
}

// The rounded box is one term: the signed distance to the inner box, minus the radius.
Solid rounded_box(const Point3& lower, const Point3& upper, double radius) {
    const Point3 centre = 0.5 * (lower + upper);
    const Vector3 half = 0.5 * (upper - lower) - Vector3::Constant(radius);
    auto excess = [=](const Point3& p) -> Vector3 { return (p - centre).cwiseAbs() - half; };
    auto value = [=](const Point3& p) {
        const Vector3 q = excess(p);
        return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0) - radius;
    };
    auto gradient = [=](const Point3& p) -> Vector3 {
        const Vector3 q = excess(p);
        const Vector3 sign = (p - centre).cwiseSign();
        if (q.maxCoeff() > 0.0) return q.cwiseMax(0.0).normalized().cwiseProduct(sign);
        Eigen::Index axis;
        q.maxCoeff(&axis);
        Vector3 g = Vector3::Zero();
        g[axis] = sign[axis];
        return g;
    };
    return Solid{{{value, gradient}}, (upper - lower).maxCoeff() / 2, Aabb(lower, upper)};
}

// Samples points along seeded rays, away from span ends and from the surface, and checks that
// span membership equals the independent membership (every term negative). Returns the number
// of points checked.
long check_membership(const Shape& shape, const Solid& solid, int rays, std::uint64_t seed) {
    test::Random random(seed);
    const Aabb from = test::enlarged(solid.region, 1.0);
    const Aabb toward = test::enlarged(solid.region, 0.05);
    long checked = 0;
    int failures = 0;
    for (int i = 0; i < rays && failures < 10; ++i) {
        const Ray ray = random.ray_between(from, toward);
        const SpanList spans = shape.spans(ray);
        const double reach = 3.0 * from.diagonal().norm() / ray.direction.norm();
        for (int sample = 0; sample < 8; ++sample) {
            const double t = random.uniform(0.0, reach);
            const Point3 p = ray.at(t);
            // 1e-9 of the size: far above rounding (1e-15), far below any feature.
            if (std::abs(solid.value(p)) < 1e-9 * solid.scale) continue;
            bool inside = false;
            for (const Span& span : spans) inside |= t > span.enter.t && t < span.exit.t;
            const bool expected = solid.value(p) < 0.0;
            EXPECT_EQ(inside, expected) << "ray " << i << " t " << t << " seed " << seed;
            EXPECT_EQ(shape.contains(p), expected) << "ray " << i << " t " << t;
            failures += inside != expected;
            ++checked;
        }
    }
    return checked;
}

void check_ready_made(const Shape& shape, const Solid& solid, std::uint64_t seed,
                      int minimum_hits) {
    ASSERT_TRUE(shape.is_solid());
    const test::PropertyCounts counts =
        test::check_shape_properties(shape, solid.surface(), 100'000, seed);
    EXPECT_EQ(counts.rays, 100'000);
    EXPECT_GT(counts.hits, minimum_hits);
    EXPECT_GT(counts.span_checks, 100'000);
    EXPECT_GT(check_membership(shape, solid, 20'000, seed + 1000), 100'000);
}

TEST(ReadyMade, SolidCylinderAlongAnyAxis) {
    const Point3 ends[][2] = {{Point3(0, -1, 0), Point3(0, 2, 0)},
                              {Point3(1, 2, 3), Point3(1, 0.5, 3)},  // downward, moved sideways
                              {Point3(-1, 0.5, 0.2), Point3(2, 0.5, 0.2)},
                              {Point3(0.3, 0.1, 1), Point3(0.3, 0.1, -2)},
                              {Point3(0.2, -0.4, 0.1), Point3(1.5, 1.3, -0.9)}};
    std::uint64_t seed = 100;
    for (const auto& end : ends) {
        const auto cylinder = make_solid_cylinder(end[0], end[1], 0.7);
        check_ready_made(*cylinder, solid_cylinder(end[0], end[1], 0.7), ++seed, 20'000);
    }
    // Axis-aligned placements are exact: the caps land on the given coordinates.
    const auto along_x = make_solid_cylinder(Point3(-1, 0.5, 0.2), Point3(2, 0.5, 0.2), 0.7);
    const auto hit = along_x->intersect(Ray{Point3(-5, 0.5, 0.2), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->geometric_normal, Normal3(-1, 0, 0));
}

TEST(ReadyMade, SolidConeAndFrustum) {
    std::uint64_t seed = 200;
    const auto cone = make_solid_cone(Point3(0.1, -1, 0.2), Point3(0.1, 1.5, 0.2), 1.0);
    check_ready_made(*cone, solid_cone(Point3(0.1, -1, 0.2), Point3(0.1, 1.5, 0.2), 1.0, 0.0),
                     ++seed, 15'000);
    const Point3 base(0.5, 0.2, -0.3), top(-0.7, 1.1, 0.9);
    const auto frustum = make_solid_cone(base, top, 0.9, 0.4);
    check_ready_made(*frustum, solid_cone(base, top, 0.9, 0.4), ++seed, 15'000);
}

TEST(ReadyMade, ThickRing) {
    const auto ring = make_thick_ring(-0.25, 0.5, 0.6, 1.0);
    check_ready_made(*ring, thick_ring(-0.25, 0.5, 0.6, 1.0), 300, 20'000);
    // Across the middle: two spans, through the wall, the hole, the wall.
    const SpanList spans = ring->spans(Ray{Point3(-3, 0, 0), Vector3(1, 0, 0)});
    ASSERT_EQ(spans.size(), 2u);
    EXPECT_DOUBLE_EQ(spans[0].enter.t, 2.0);
    EXPECT_DOUBLE_EQ(spans[0].exit.t, 2.4);
    EXPECT_DOUBLE_EQ(spans[1].enter.t, 3.6);
    EXPECT_DOUBLE_EQ(spans[1].exit.t, 4.0);
    // Down through the hole: nothing; down onto the wall: the top end at y = 0.5.
    EXPECT_FALSE(ring->intersect(Ray{Point3(0, 3, 0), Vector3(0, -1, 0)}));
    const auto hit = ring->intersect(Ray{Point3(0.8, 3, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 2.5);
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0));
    // From inside the hole, outward: the inner wall, its normal pointing into the hole.
    const auto inner = ring->intersect(Ray{Point3(0, 0, 0), Vector3(0, 0, 1)});
    ASSERT_TRUE(inner);
    EXPECT_DOUBLE_EQ(inner->t, 0.6);
    EXPECT_TRUE(inner->geometric_normal.isApprox(Normal3(0, 0, -1)));
    EXPECT_TRUE(inner->front_face);
}

TEST(ReadyMade, Bowl) {
    const auto shape = make_bowl(1.0, 0.85);
    check_ready_made(*shape, bowl(1.0, 0.85), 400, 15'000);
    // Straight down the axis: into the bowl, onto its inner bottom at y = -0.85.
    const auto hit = shape->intersect(Ray{Point3(0, 2, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 2.85);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, 1, 0)));  // out of the material
    // Onto the rim: the flat annulus at y = 0.
    const auto rim = shape->intersect(Ray{Point3(0.9, 2, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(rim);
    EXPECT_DOUBLE_EQ(rim->t, 2.0);
    EXPECT_EQ(rim->geometric_normal, Normal3(0, 1, 0));
    // From below: the outer surface.
    const auto outer = shape->intersect(Ray{Point3(0, -3, 0), Vector3(0, 1, 0)});
    ASSERT_TRUE(outer);
    EXPECT_DOUBLE_EQ(outer->t, 2.0);
    EXPECT_TRUE(outer->geometric_normal.isApprox(Normal3(0, -1, 0)));
}

TEST(ReadyMade, RoundedBox) {
    const Point3 lower(-1, -0.5, -0.75), upper(1.2, 0.5, 0.75);
    const auto box = make_rounded_box(lower, upper, 0.2);
    check_ready_made(*box, rounded_box(lower, upper, 0.2), 500, 25'000);
    // A flat face exactly where the box says, and a corner on the inner corner's sphere.
    auto hit = box->intersect(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->geometric_normal, Normal3(-1, 0, 0));
    const Point3 corner = upper - Vector3::Constant(0.2);
    const Vector3 diagonal = Vector3(1, 1, 1).normalized();
    hit = box->intersect(Ray{corner + 5 * diagonal, -diagonal});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 4.8, 1e-14);
    EXPECT_NEAR((hit->geometric_normal - diagonal).norm(), 0.0, 1e-14);
    // Rays along the flat faces' tangent lines onto the edge cylinders: no phantom surface.
    hit = box->intersect(Ray{Point3(0, 5, 0.55), Vector3(0, -1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 4.5);
}

TEST(ReadyMade, AreCsgOperands) {
    const auto box = make_rounded_box(Point3(-1, -1, -1), Point3(1, 1, 1), 0.25);
    const auto ring = make_thick_ring(-2, 2, 0.4, 0.6);
    const Boolean drilled(BooleanOperation::Difference, box, ring);
    // A rounded box with a tube-shaped groove: the ring's wall is cut out of the box, the plug
    // of box material inside the ring's hole stays.
    const SpanList spans = drilled.spans(Ray{Point3(0.5, 5, 0), Vector3(0, -1, 0)});
    EXPECT_TRUE(spans.empty());  // x = 0.5 lies in the ring's wall: drilled away
    const SpanList plug = drilled.spans(Ray{Point3(0, 5, 0), Vector3(0, -1, 0)});
    ASSERT_EQ(plug.size(), 1u);
    EXPECT_DOUBLE_EQ(plug[0].enter.t, 4.0);
    EXPECT_DOUBLE_EQ(plug[0].exit.t, 6.0);
    EXPECT_TRUE(drilled.contains(Point3(0.8, 0, 0)));
    EXPECT_FALSE(drilled.contains(Point3(0.5, 0, 0)));
}

TEST(ReadyMade, BadParametersThrowNamingTheParameter) {
    auto message = [](auto make) -> std::string {
        try {
            make();
        } catch (const InvalidParameter& error) {
            return error.what();
        }
        return "no exception";
    };
    EXPECT_NE(message([] {
                  make_solid_cylinder(Point3(0, 0, 0), Point3(0, 0, 0), 1);
              }).find("make_solid_cylinder: top"),
              std::string::npos);
    EXPECT_NE(
        message([] { make_solid_cylinder(Point3(0, 0, 0), Point3(0, 1, 0), -1); }).find("radius"),
        std::string::npos);
    EXPECT_NE(message([] { make_solid_cone(Point3(0, 0, 0), Point3(0, 1, 0), 0, 0); }).find("Cone"),
              std::string::npos);
    EXPECT_NE(message([] { make_thick_ring(0, 1, 1, 0.5); }).find("outer_radius"),
              std::string::npos);
    EXPECT_NE(message([] { make_thick_ring(1, 1, 0.5, 1); }).find("y_max"), std::string::npos);
    EXPECT_NE(message([] { make_bowl(1, 0); }).find("inner_radius"), std::string::npos);
    EXPECT_NE(message([] { make_bowl(1, 2); }).find("outer_radius"), std::string::npos);
    EXPECT_NE(message([] {
                  make_rounded_box(Point3(0, 0, 0), Point3(1, 1, 0.4), 0.2);
              }).find("make_rounded_box: upper"),
              std::string::npos);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_NE(
        message([&] { make_rounded_box(Point3(nan, 0, 0), Point3(1, 1, 1), 0.2); }).find("lower"),
        std::string::npos);
}

}  // namespace
}  // namespace csgrt
