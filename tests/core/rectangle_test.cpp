#include "csgrt/core/rectangle.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "csgrt/core/error.h"
#include "support/error_of.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using test::error_of;

// 2 along z, 3 along x: normal (0, 0, 2) x (3, 0, 0) = (0, 6, 0), i.e. +y.
const Rectangle kRectangle(Point3(0, 0, 0), Vector3(0, 0, 2), Vector3(3, 0, 0));

TEST(Rectangle, AnalyticHitWithUv) {
    const std::optional<Hit> hit =
        kRectangle.intersect(Ray{Point3(1.5, 4, 0.5), Vector3(0, -2, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 2.0);
    EXPECT_EQ(hit->point, Point3(1.5, 0, 0.5));
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0));
    EXPECT_TRUE(hit->front_face);
    EXPECT_EQ(hit->uv, Vector2(0.25, 0.5));  // (s, t) along edge_a, edge_b
    EXPECT_EQ(hit->shape, &kRectangle);
}

TEST(Rectangle, ParallelogramNotItsBoundingRectangle) {
    // corner (1, 1, 1), edges (2, 0, 0) and (1, 0, 2): normal (0, -4, 0) -> -y.
    const Rectangle parallelogram(Point3(1, 1, 1), Vector3(2, 0, 0), Vector3(1, 0, 2));
    const std::optional<Hit> hit = test::expect_hit_from_behind(
        parallelogram, Ray{Point3(2.5, 3, 2), Vector3(0, -1, 0)}, 2.0, Normal3(0, -1, 0));
    ASSERT_TRUE(hit);  // at s = t = 1/2
    EXPECT_EQ(hit->uv, Vector2(0.5, 0.5));
    // Inside the bounding box, outside the parallelogram: s = -0.1 at t = 0.5.
    EXPECT_FALSE(parallelogram.intersect(Ray{Point3(1.3, 3, 2), Vector3(0, -1, 0)}));
}

TEST(Rectangle, EdgesAndCornersBelongToIt) {
    for (const Point3& target :
         {Point3(0, 0, 0), Point3(3, 0, 0), Point3(0, 0, 2), Point3(3, 0, 2), Point3(1.5, 0, 0),
          Point3(3, 0, 1), Point3(1.5, 0, 2), Point3(0, 0, 1)}) {
        EXPECT_TRUE(kRectangle.intersect(Ray{target + Vector3(0, 1, 0), Vector3(0, -1, 0)}))
            << target.transpose();
    }
    // Outside an edge by more than the rounding of s = q . dual (2 u relative) is outside.
    const double past = next_up(next_up(next_up(next_up(3.0))));
    EXPECT_FALSE(kRectangle.intersect(Ray{Point3(past, 1, 1), Vector3(0, -1, 0)}));
    EXPECT_FALSE(kRectangle.intersect(Ray{Point3(1, 1, -1e-300), Vector3(0, -1, 0)}));
}

TEST(Rectangle, ParallelRaysNeverHitEvenInThePlane) {
    test::expect_misses(kRectangle, {Ray{Point3(-1, 0, 1), Vector3(1, 0, 0)},
                                     Ray{Point3(-1, 0.5, 1), Vector3(1, 0, 0.1)}});
}

TEST(Rectangle, RayStartingOnItAndPointingAway) {
    test::expect_hit_only_at_start(kRectangle, Ray{Point3(1, 0, 1), Vector3(0.3, 1, 0.2)});
}

TEST(Rectangle, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(1, 4, 1), Vector3(0, -1, 0)};  // crosses at t = 4
    test::expect_interval_honoured(kRectangle, ray, 4.0);
}

TEST(Rectangle, InvalidRaysNeverHit) {
    test::expect_invalid_rays_miss(kRectangle, Ray{Point3(1, 4, 1), Vector3(0, -1, 0)});
}

TEST(Rectangle, RejectsBadParametersNamingThem) {
    const Point3 o(0, 0, 0);
    const Vector3 x(1, 0, 0), z(0, 0, 1);
    EXPECT_NE(error_of([&] { Rectangle(o, Vector3(0, 0, 0), z); }).find("Rectangle: edge_a"),
              std::string::npos);
    EXPECT_NE(error_of([&] { Rectangle(o, x, Vector3(0, 0, 0)); }).find("Rectangle: edge_b"),
              std::string::npos);
    const std::string parallel = error_of([&] { Rectangle(o, x, Vector3(-3, 0, 0)); });
    EXPECT_NE(parallel.find("Rectangle: edge_b must be not parallel to edge_a"), std::string::npos)
        << parallel;
    EXPECT_NE(error_of([&] { Rectangle(o, Vector3(std::nan(""), 0, 0), z); }).find("edge_a"),
              std::string::npos);
    EXPECT_NE(error_of([&] { Rectangle(Point3(0, 0, kInfinity), x, z); }).find("corner"),
              std::string::npos);
    // Tiny and huge edges are valid.
    const Rectangle tiny(o, Vector3(1e-200, 0, 0), Vector3(0, 0, 1e-200));
    EXPECT_EQ(tiny.normal(), Normal3(0, -1, 0));
    EXPECT_TRUE(tiny.intersect(Ray{Point3(5e-201, 1, 5e-201), Vector3(0, -1, 0)}));
    const Rectangle huge(o, Vector3(1e200, 0, 0), Vector3(0, 0, 1e200));
    EXPECT_TRUE(huge.intersect(Ray{Point3(5e199, 1, 5e199), Vector3(0, -1, 0)}));
}

TEST(Rectangle, MatchesALongDoubleLinearSolve) {
    // The independent answer: solve o + t d = c + s a + r b as a 3x3 system in long double.
    using LongMatrix = Eigen::Matrix<long double, 3, 3>;
    using LongVector = Eigen::Matrix<long double, 3, 1>;
    test::Random random(61);
    int compared = 0, hits = 0;
    for (int i = 0; i < 50000; ++i) {
        const Rectangle rectangle(random.in_box(Aabb(Point3(-5, -5, -5), Point3(5, 5, 5))),
                                  random.unit_vector() * random.uniform(0.2, 4),
                                  random.unit_vector() * random.uniform(0.2, 4));
        const Ray ray =
            random.ray_between(test::enlarged(rectangle.bounds(), 1.0), rectangle.bounds());
        LongMatrix system;
        system << rectangle.edge_a().cast<long double>(), rectangle.edge_b().cast<long double>(),
            -ray.direction.cast<long double>();
        const LongVector rhs = (ray.origin - rectangle.corner()).cast<long double>();
        const LongVector solution = system.fullPivLu().solve(rhs);
        const long double s = solution[0], r = solution[1], t = solution[2];
        // Decided beyond double rounding: 1e-9 away from every edge and from t = 0.
        const long double margin = 1e-9L;
        if (std::min({std::abs(s), std::abs(1 - s), std::abs(r), std::abs(1 - r)}) < margin ||
            std::abs(t) < margin)
            continue;
        ++compared;
        const bool expected = s >= 0 && s <= 1 && r >= 0 && r <= 1 && t >= 0;
        const std::optional<Hit> hit = rectangle.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected) << "ray " << i;
        if (!hit) continue;
        ++hits;
        // The relative error of a 3x3 solve grows with its condition number (grazing rays):
        // allow 64 u times it.
        const double condition = double(system.norm() * system.inverse().norm());
        EXPECT_NEAR(hit->t, double(t), 64 * kUnitRoundoff * condition * (1 + std::abs(double(t))))
            << "ray " << i;
        EXPECT_NEAR(hit->uv.x(), double(s), 1e-6);  // uv are kept as float
        EXPECT_NEAR(hit->uv.y(), double(r), 1e-6);
    }
    EXPECT_GT(compared, 49000);
    EXPECT_GT(hits, 10000);
}

TEST(Rectangle, PropertiesOnRandomRays) {
    const Rectangle rectangle(Point3(0.3, -1.2, 2.0), Vector3(1.5, 0.2, -0.4),
                              Vector3(0.3, 1.1, 0.9));
    const test::SurfaceDescription surface =
        test::plane_surface(rectangle.corner(), rectangle.normal(), 1.5, rectangle.bounds());
    const test::PropertyCounts counts =
        test::check_shape_properties(rectangle, surface, 100000, 62);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 20000);
}

}  // namespace
}  // namespace csgrt
