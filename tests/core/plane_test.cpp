#include "csgrt/core/plane.h"

#include <gtest/gtest.h>

#include "csgrt/core/error.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

const Plane kGround(Point3(0, 1, 0), Normal3(0, 3, 0));

TEST(Plane, AnalyticHitFromAbove) {
    const std::optional<Hit> hit = kGround.intersect(Ray{Point3(0.5, 5, -2), Vector3(0, -2, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 2.0);
    EXPECT_EQ(hit->point, Point3(0.5, 1, -2));
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0));  // normalised, not turned to the ray
    EXPECT_TRUE(hit->front_face);
    EXPECT_EQ(hit->shape, &kGround);
}

TEST(Plane, ObliquePlaneAndRay) {
    // (p - (1, 2, 3)) . (1, 1, 1) = 0 along o = 0, d = (1, 1, 1): t = 6 / 3 = 2.
    const Plane plane(Point3(1, 2, 3), Normal3(1, 1, 1));
    const std::optional<Hit> hit = plane.intersect(Ray{Point3(0, 0, 0), Vector3(1, 1, 1)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 2.0, 8 * kUnitRoundoff);
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(1, 1, 1).normalized(), 1e-15));
}

TEST(Plane, FromBelowKeepsTheNormalAndIsBackFacing) {
    test::expect_hit_from_behind(kGround, Ray{Point3(0, -3, 0), Vector3(0, 1, 0)}, 4.0,
                                 Normal3(0, 1, 0));
}

TEST(Plane, PointingAwayMisses) {
    EXPECT_FALSE(kGround.intersect(Ray{Point3(0, 5, 0), Vector3(0.3, 1, 0)}));
    EXPECT_FALSE(kGround.occluded(Ray{Point3(0, 5, 0), Vector3(0.3, 1, 0)}));
}

TEST(Plane, ParallelRaysNeverHitEvenInThePlane) {
    test::expect_misses(kGround, {Ray{Point3(0, 2, 0), Vector3(1, 0, 0)},  // above, parallel
                                  Ray{Point3(0, 1, 0), Vector3(1, 0, 0)},  // lying in the plane
                                  Ray{Point3(3, 1, -2), Vector3(0, 0, -5)}});
}

TEST(Plane, RayStartingOnThePlane) {
    // A ray from the surface (t = 0) hits it when the interval includes 0 and not otherwise:
    // that is what a spawned ray needs its t_min for.
    test::expect_hit_only_at_start(kGround, Ray{Point3(0.25, 1, 0.5), Vector3(1, -1, 0)});
}

TEST(Plane, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(0, 5, 0), Vector3(0, -1, 0)};  // crosses at t = 4
    test::expect_interval_honoured(kGround, ray, 4.0);
    // A negative interval reaches behind the origin.
    const Ray backwards{Point3(0, 5, 0), Vector3(0, 1, 0), -kInfinity, 0.0};
    ASSERT_TRUE(kGround.intersect(backwards));
    EXPECT_EQ(kGround.intersect(backwards)->t, -4.0);
}

TEST(Plane, InvalidRaysNeverHit) {
    test::expect_invalid_rays_miss(kGround, Ray{Point3(0, 5, 0), Vector3(0, -1, 0)});
}

TEST(Plane, RejectsBadParametersNamingThem) {
    const auto message = [](const Point3& point, const Normal3& normal) {
        try {
            Plane(point, normal);
        } catch (const InvalidParameter& error) {
            return std::string(error.what());
        }
        return std::string("no exception");
    };
    EXPECT_NE(message(Point3(0, 0, 0), Normal3(0, 0, 0)).find("Plane: normal"), std::string::npos);
    EXPECT_NE(message(Point3(0, 0, 0), Normal3(0, std::nan(""), 1)).find("normal"),
              std::string::npos);
    EXPECT_NE(message(Point3(kInfinity, 0, 0), Normal3(0, 1, 0)).find("Plane: point"),
              std::string::npos);
    // Tiny and huge normals are fine: only the direction matters.
    EXPECT_EQ(Plane(Point3(0, 0, 0), Normal3(0, 1e-300, 0)).normal(), Normal3(0, 1, 0));
    EXPECT_EQ(Plane(Point3(0, 0, 0), Normal3(0, 0, 1e300)).normal(), Normal3(0, 0, 1));
}

TEST(Plane, UvAreFrameCoordinatesWrappedIntoTheUnitSquare) {
    const Plane plane(Point3(0, 0, 0), Normal3(0, 1, 0));  // frame: x_axis +x, z_axis +z
    const std::optional<Hit> hit = plane.intersect(Ray{Point3(2.25, 1, -0.75), Vector3(0, -1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->uv, Vector2(0.25, 0.25));
    const std::optional<Hit> tiny = plane.intersect(Ray{Point3(-1e-20, 1, 0.5), Vector3(0, -1, 0)});
    ASSERT_TRUE(tiny);
    EXPECT_GE(tiny->uv.x(), 0.0);
    EXPECT_LT(tiny->uv.x(), 1.0);
}

TEST(SurfaceFrame, OrthonormalRightHandedAndYUp) {
    const SurfaceFrame up = SurfaceFrame::around(Normal3(0, 1, 0));
    EXPECT_EQ(up.x_axis, Vector3(1, 0, 0));
    EXPECT_EQ(up.z_axis, Vector3(0, 0, 1));
    const SurfaceFrame down = SurfaceFrame::around(Normal3(0, -1, 0));  // half turn about z
    EXPECT_EQ(down.x_axis, Vector3(-1, 0, 0));
    EXPECT_EQ(down.z_axis, Vector3(0, 0, 1));
    test::Random random(3);
    std::vector<Normal3> normals = {Normal3(1, 0, 0), Normal3(-1, 0, 0), Normal3(0, 0, 1),
                                    Normal3(0, 0, -1), Normal3(0, -1, 1e-9).normalized()};
    for (int i = 0; i < 10000; ++i) normals.push_back(random.unit_vector());
    for (const Normal3& n : normals) {
        const SurfaceFrame frame = SurfaceFrame::around(n);
        // Each entry is a few roundings of numbers <= 1: 8 u covers them.
        const double tolerance = 8 * kUnitRoundoff;
        EXPECT_NEAR(frame.x_axis.norm(), 1.0, tolerance);
        EXPECT_NEAR(frame.z_axis.norm(), 1.0, tolerance);
        EXPECT_NEAR(frame.x_axis.dot(n), 0.0, tolerance);
        EXPECT_NEAR(frame.z_axis.dot(n), 0.0, tolerance);
        EXPECT_NEAR(frame.x_axis.dot(frame.z_axis), 0.0, tolerance);
        // Right-handed as (x, y, z): x cross y = z.
        EXPECT_TRUE(frame.x_axis.cross(n).isApprox(frame.z_axis, tolerance));
    }
}

TEST(Plane, MatchesALongDoubleSolve) {
    test::Random random(41);
    for (int i = 0; i < 20000; ++i) {
        const Plane plane(random.in_box(Aabb(Point3(-10, -10, -10), Point3(10, 10, 10))),
                          random.unit_vector() * random.uniform(0.1, 10));
        const Ray ray = random.ray_between(Aabb(Point3(-20, -20, -20), Point3(20, 20, 20)),
                                           Aabb(Point3(-20, -20, -20), Point3(20, 20, 20)));
        const test::LongPlaneSolve solve =
            test::long_plane_solve(plane.point(), plane.normal(), ray);
        const std::optional<Hit> hit = plane.intersect(ray);
        ASSERT_EQ(hit.has_value(), solve.t >= 0) << "ray " << i;
        if (!hit) continue;
        EXPECT_NEAR(hit->t, static_cast<double>(solve.t), static_cast<double>(solve.bound()))
            << "ray " << i;
    }
}

TEST(Plane, PropertiesOnRandomRays) {
    const Plane plane(Point3(0.3, -1.2, 2.0), Normal3(0.2, 1.0, -0.4));
    const test::SurfaceDescription surface = test::plane_surface(
        plane.point(), plane.normal(), 2.0,
        Aabb(plane.point() - Vector3::Constant(2.0), plane.point() + Vector3::Constant(2.0)));
    const test::PropertyCounts counts = test::check_shape_properties(plane, surface, 100000, 17);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 30000);
    EXPECT_EQ(counts.span_checks, 0);  // not a solid
}

}  // namespace
}  // namespace csgrt
