#include "csgrt/core/disk.h"

#include <gtest/gtest.h>

#include "csgrt/core/error.h"
#include "support/error_of.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using LongVector = Eigen::Matrix<long double, 3, 1>;

using test::error_of;

const Disk kDisk(Point3(0, 1, 0), Normal3(0, 2, 0), 2.0);

TEST(Disk, AnalyticHitWithUv) {
    const std::optional<Hit> hit = kDisk.intersect(Ray{Point3(1, 5, 1), Vector3(0, -0.5, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 8.0);
    EXPECT_EQ(hit->point, Point3(1, 1, 1));
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 1, 0));
    EXPECT_TRUE(hit->front_face);
    // r = sqrt(2) of 2; phi = atan2(x, z) = pi / 4 in the y-up frame.
    EXPECT_NEAR(hit->uv.x(), std::sqrt(0.5), 4 * kUnitRoundoff);
    EXPECT_NEAR(hit->uv.y(), 0.125, 4 * kUnitRoundoff);
    EXPECT_EQ(hit->shape, &kDisk);
}

TEST(Disk, FromBelowKeepsTheNormal) {
    test::expect_hit_from_behind(kDisk, Ray{Point3(0.5, -1, 0), Vector3(0, 1, 0)}, 2.0,
                                 Normal3(0, 1, 0));
}

TEST(Disk, RimBelongsToTheDisk) {
    // (2, 1, 0) is exactly on the rim: 2^2 <= 2^2. One ulp outside is a miss.
    EXPECT_TRUE(kDisk.intersect(Ray{Point3(2, 5, 0), Vector3(0, -1, 0)}));
    EXPECT_TRUE(kDisk.intersect(Ray{Point3(0, 5, -2), Vector3(0, -1, 0)}));
    EXPECT_FALSE(kDisk.intersect(Ray{Point3(next_up(2.0), 5, 0), Vector3(0, -1, 0)}));
    EXPECT_FALSE(kDisk.occluded(Ray{Point3(next_up(2.0), 5, 0), Vector3(0, -1, 0)}));
    // Oblique ray onto the rim point (0, 1, 2).
    const Point3 origin(3, 4, -1);
    EXPECT_TRUE(kDisk.intersect(Ray{origin, Point3(0, 1, 2) - origin}));
}

TEST(Disk, MissesOutsideAndPointingAway) {
    EXPECT_FALSE(kDisk.intersect(Ray{Point3(1.5, 5, 1.5), Vector3(0, -1, 0)}));  // r = 2.12
    EXPECT_FALSE(kDisk.intersect(Ray{Point3(0, 5, 0), Vector3(0, 1, 0)}));
    EXPECT_FALSE(kDisk.occluded(Ray{Point3(0, 5, 0), Vector3(0, 1, 0)}));
}

TEST(Disk, ParallelRaysNeverHitEvenInThePlane) {
    test::expect_misses(kDisk, {Ray{Point3(-5, 1, 0), Vector3(1, 0, 0)},  // in the plane, across
                                Ray{Point3(-5, 1.5, 0), Vector3(1, 0, 0.2)}});
}

TEST(Disk, RayStartingOnTheDisk) {
    test::expect_hit_only_at_start(kDisk, Ray{Point3(0.5, 1, 0.5), Vector3(1, 1, 0)});
}

TEST(Disk, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(0.5, 5, 0), Vector3(0, -1, 0)};  // crosses at t = 4
    test::expect_interval_honoured(kDisk, ray, 4.0);
}

TEST(Disk, InvalidRaysNeverHit) {
    test::expect_invalid_rays_miss(kDisk, Ray{Point3(0, 5, 0), Vector3(0, -1, 0)});
}

TEST(Disk, RejectsBadParametersNamingThem) {
    const Point3 o(0, 0, 0);
    const Normal3 up(0, 1, 0);
    EXPECT_NE(error_of([&] { Disk(o, up, 0.0); }).find("Disk: radius"), std::string::npos);
    EXPECT_NE(error_of([&] { Disk(o, up, -1.0); }).find("Disk: radius"), std::string::npos);
    EXPECT_NE(error_of([&] { Disk(o, up, std::nan("")); }).find("Disk: radius"), std::string::npos);
    EXPECT_NE(error_of([&] { Disk(o, up, kInfinity); }).find("Disk: radius"), std::string::npos);
    EXPECT_NE(error_of([&] { Disk(o, Normal3(0, 0, 0), 1.0); }).find("Disk: normal"),
              std::string::npos);
    EXPECT_NE(error_of([&] { Disk(Point3(0, std::nan(""), 0), up, 1.0); }).find("Disk: center"),
              std::string::npos);
}

TEST(Disk, BoundsHoldTheRim) {
    test::Random random(51);
    for (int i = 0; i < 1000; ++i) {
        const Disk disk(random.in_box(Aabb(Point3(-9, -9, -9), Point3(9, 9, 9))),
                        random.unit_vector(), random.uniform(0.1, 5));
        const Aabb box = disk.bounds();
        for (int k = 0; k < 64; ++k) {
            const double phi = kTwoPi * k / 64;
            // The rim in long double, rounded once: inside the bounds up to that rounding.
            const LongVector rim =
                disk.center().cast<long double>() +
                (long double)disk.radius() *
                    (std::cos((long double)phi) * disk.frame().z_axis.cast<long double>() +
                     std::sin((long double)phi) * disk.frame().x_axis.cast<long double>());
            EXPECT_TRUE(box.contains(rim.cast<double>())) << "disk " << i << " angle " << k;
        }
    }
}

TEST(Disk, MatchesALongDoubleSolve) {
    test::Random random(52);
    int compared = 0, hits = 0;
    for (int i = 0; i < 50000; ++i) {
        const Disk disk(random.in_box(Aabb(Point3(-5, -5, -5), Point3(5, 5, 5))),
                        random.unit_vector(), random.uniform(0.5, 3));
        const Ray ray = random.ray_between(test::enlarged(disk.bounds(), 2.0), disk.bounds());
        const test::LongPlaneSolve solve =
            test::long_plane_solve(disk.center(), disk.normal(), ray);
        const long double t = solve.t;
        const long double squared = solve.offset().squaredNorm();
        const long double radius_squared = square(disk.radius());
        // Away from the rim by more than double rounding can move a point (1e-9 relative).
        if (std::abs(squared - radius_squared) < 1e-9L * radius_squared) continue;
        ++compared;
        const bool expected = t >= 0 && squared <= radius_squared;
        const std::optional<Hit> hit = disk.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected) << "ray " << i;
        if (!hit) continue;
        ++hits;
        // The plane solve's forward error, as for the plane.
        EXPECT_NEAR(hit->t, double(t), double(solve.bound())) << "ray " << i;
    }
    EXPECT_GT(compared, 49000);
    EXPECT_GT(hits, 10000);
}

TEST(Disk, PropertiesOnRandomRays) {
    const Disk disk(Point3(0.3, -1.2, 2.0), Normal3(0.2, 1.0, -0.4), 1.7);
    const test::SurfaceDescription surface =
        test::plane_surface(disk.center(), disk.normal(), disk.radius(), disk.bounds());
    const test::PropertyCounts counts = test::check_shape_properties(disk, surface, 100000, 53);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 20000);
    // Every hit lies within the radius, up to the rounding of the point (a few u of its size).
    test::Random random(53);
    for (int i = 0; i < 100000; ++i) {
        const Ray ray = random.ray_between(test::enlarged(disk.bounds(), 1.0), disk.bounds());
        const std::optional<Hit> hit = disk.intersect(ray);
        if (!hit) continue;
        const double size = hit->point.norm() + disk.radius();
        EXPECT_LE((hit->point - disk.center()).norm(), disk.radius() + 16 * kUnitRoundoff * size);
        EXPECT_GE(hit->uv.minCoeff(), 0.0);
        EXPECT_LE(hit->uv.maxCoeff(), 1.0);
    }
}

}  // namespace
}  // namespace csgrt
