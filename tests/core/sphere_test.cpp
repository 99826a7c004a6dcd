#include "csgrt/core/sphere.h"

#include <gtest/gtest.h>

#include "csgrt/core/error.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

const Sphere kUnitSphere(Point3(0, 0, 0), 1.0);

TEST(Sphere, AnalyticHitFromOutside) {
    const std::optional<Hit> hit = kUnitSphere.intersect(Ray{Point3(0, 0, -5), Vector3(0, 0, 2)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 2.0);
    EXPECT_TRUE(hit->point.isApprox(Point3(0, 0, -1)));
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, 0, -1)));
    EXPECT_TRUE(hit->front_face);
    EXPECT_EQ(hit->shape, &kUnitSphere);
}

TEST(Sphere, MissAndPointingAway) {
    EXPECT_FALSE(kUnitSphere.intersect(Ray{Point3(0, 2, -5), Vector3(0, 0, 1)}));
    EXPECT_FALSE(kUnitSphere.intersect(Ray{Point3(0, 0, -5), Vector3(0, 0, -1)}));
    EXPECT_FALSE(kUnitSphere.occluded(Ray{Point3(0, 0, -5), Vector3(0, 0, -1)}));
}

TEST(Sphere, FromInsideHitsTheFarSideFromBehind) {
    const std::optional<Hit> hit = kUnitSphere.intersect(Ray{Point3(0, 0.5, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, std::sqrt(0.75), 4 * kUnitRoundoff);
    EXPECT_FALSE(hit->front_face);
    const SpanList spans = kUnitSphere.spans(Ray{Point3(0, 0.5, 0), Vector3(1, 0, 0)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_LT(spans[0].enter.t, 0.0);  // the span began behind the origin
}

TEST(Sphere, TangentRayTouchesOnce) {
    const Ray tangent{Point3(-5, 1, 0), Vector3(1, 0, 0)};
    const std::optional<Hit> hit = kUnitSphere.intersect(tangent);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 5.0, 1e-7);  // a double root is only determined to sqrt(u)
    const SpanList spans = kUnitSphere.spans(tangent);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_NEAR(spans[0].enter.t, spans[0].exit.t, 1e-7);
}

TEST(Sphere, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(0, 0, -5), Vector3(0, 0, 1)};  // roots at 4 and 6
    Ray clipped = ray;
    clipped.t_max = 3.999;
    EXPECT_FALSE(kUnitSphere.intersect(clipped));
    clipped.t_max = 4.0;
    EXPECT_TRUE(kUnitSphere.intersect(clipped));
    clipped = ray;
    clipped.t_min = 4.5;
    ASSERT_TRUE(kUnitSphere.intersect(clipped));
    EXPECT_DOUBLE_EQ(kUnitSphere.intersect(clipped)->t, 6.0);
    clipped.t_min = 6.001;
    EXPECT_FALSE(kUnitSphere.intersect(clipped));
    EXPECT_FALSE(kUnitSphere.occluded(clipped));
}

TEST(Sphere, InvalidRaysNeverHit) {
    test::expect_invalid_rays_miss(kUnitSphere, Ray{Point3(0, 0, -5), Vector3(0, 0, 1)});
}

TEST(Sphere, RejectsBadParameters) {
    EXPECT_THROW(Sphere(Point3(0, 0, 0), 0.0), InvalidParameter);
    EXPECT_THROW(Sphere(Point3(0, 0, 0), -1.0), InvalidParameter);
    EXPECT_THROW(Sphere(Point3(0, 0, 0), std::nan("")), InvalidParameter);
    EXPECT_THROW(Sphere(Point3(0, kInfinity, 0), 1.0), InvalidParameter);
}

TEST(Sphere, UvFollowsTheBookConvention) {
    const std::optional<Hit> top = kUnitSphere.intersect(Ray{Point3(0, 5, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(top);
    EXPECT_NEAR(top->uv.y(), 1.0, 1e-12);  // theta = 0 at +y
    const std::optional<Hit> side = kUnitSphere.intersect(Ray{Point3(5, 0, 0), Vector3(-1, 0, 0)});
    ASSERT_TRUE(side);
    EXPECT_NEAR(side->uv.x(), 0.25, 1e-12);  // phi = atan2(x, z) = pi/2 at +x
    EXPECT_NEAR(side->uv.y(), 0.5, 1e-12);
}

TEST(Sphere, PropertiesOnRandomRays) {
    const Sphere sphere(Point3(0.3, -1.2, 2.0), 1.7);
    const test::SurfaceDescription surface =
        test::sphere_surface(sphere.center(), sphere.radius(), sphere.bounds());
    const test::PropertyCounts counts = test::check_shape_properties(sphere, surface, 100000, 11);
    EXPECT_GT(counts.hits, 30000);
    EXPECT_GT(counts.span_checks, 100000);
}

TEST(Sphere, SmallSphereFarAwayStaysAccurate) {
    // The case the Ray Tracing Gems discriminant exists for: radius 1e-3 at distance 1e6.
    const Sphere sphere(Point3(1e6, 0, 0), 1e-3);
    test::Random random(12);
    int hits = 0;
    for (int i = 0; i < 10000; ++i) {
        const Point3 target = sphere.center() + random.unit_vector() * 0.999e-3 * random.uniform();
        const Ray ray{Point3(0, 0, 0), target};
        const std::optional<Hit> hit = sphere.intersect(ray);
        ASSERT_TRUE(hit) << "ray " << i;
        ++hits;
        // |p - c| = r within the rounding of coordinates of size 1e6: 8 u 1e6 ~ 1e-9.
        EXPECT_NEAR((ray.at(hit->t) - sphere.center()).norm(), 1e-3, 8 * kUnitRoundoff * 1e6);
    }
    EXPECT_EQ(hits, 10000);
}

}  // namespace
}  // namespace csgrt
