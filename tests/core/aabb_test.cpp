#include "csgrt/core/aabb.h"

#include <gtest/gtest.h>

#include "support/random.h"

namespace csgrt {
namespace {

const Aabb kUnitBox(Point3(0, 0, 0), Point3(1, 1, 1));

TEST(Aabb, EmptyBoxExtendsToWhatItIsGiven) {
    Aabb box;
    EXPECT_TRUE(box.is_empty());
    EXPECT_EQ(box.surface_area(), 0.0);
    box.extend(Point3(1, 2, 3));
    EXPECT_FALSE(box.is_empty());
    EXPECT_EQ(box.lower, Point3(1, 2, 3));
    EXPECT_EQ(box.upper, Point3(1, 2, 3));
    box.extend(Aabb(Point3(-1, 0, 0), Point3(0, 5, 0)));
    EXPECT_EQ(box.lower, Point3(-1, 0, 0));
    EXPECT_EQ(box.upper, Point3(1, 5, 3));
    EXPECT_DOUBLE_EQ(kUnitBox.surface_area(), 6.0);
}

TEST(Aabb, OverlapAndJoin) {
    const Aabb other(Point3(0.5, 0.5, 0.5), Point3(2, 2, 2));
    const Aabb both = overlap(kUnitBox, other);
    EXPECT_EQ(both.lower, Point3(0.5, 0.5, 0.5));
    EXPECT_EQ(both.upper, Point3(1, 1, 1));
    EXPECT_TRUE(overlap(kUnitBox, Aabb(Point3(2, 2, 2), Point3(3, 3, 3))).is_empty());
    EXPECT_EQ(join(kUnitBox, other).upper, Point3(2, 2, 2));
}

TEST(Aabb, SlabTestAnalytic) {
    double t0, t1;
    const Ray ray{Point3(-1, 0.5, 0.5), Vector3(2, 0, 0)};
    ASSERT_TRUE(kUnitBox.intersect(ray, ray.direction.cwiseInverse(), t0, t1));
    EXPECT_DOUBLE_EQ(t0, 0.5);
    EXPECT_NEAR(t1, 1.0, 4 * gamma(3));
    EXPECT_FALSE(kUnitBox.intersect(Ray{Point3(-1, 1.5, 0.5), Vector3(1, 0, 0)}));
    // Pointing away.
    EXPECT_FALSE(kUnitBox.intersect(Ray{Point3(-1, 0.5, 0.5), Vector3(-1, 0, 0)}));
}

TEST(Aabb, IntervalIsHonouredAtBothEnds) {
    const Ray before{Point3(-1, 0.5, 0.5), Vector3(1, 0, 0), 0.0, 0.9};
    EXPECT_FALSE(kUnitBox.intersect(before));
    const Ray after{Point3(-1, 0.5, 0.5), Vector3(1, 0, 0), 2.1, kInfinity};
    EXPECT_FALSE(kUnitBox.intersect(after));
    const Ray touching_end{Point3(-1, 0.5, 0.5), Vector3(1, 0, 0), 0.0, 1.0};
    EXPECT_TRUE(kUnitBox.intersect(touching_end));
}

TEST(Aabb, ZeroDirectionComponentsAndSignedZero) {
    // Parallel to a slab, inside it: hit; outside it: miss; -0 behaves like +0.
    for (double zero : {0.0, -0.0}) {
        EXPECT_TRUE(kUnitBox.intersect(Ray{Point3(-1, 0.5, 0.5), Vector3(1, zero, zero)}));
        EXPECT_FALSE(kUnitBox.intersect(Ray{Point3(-1, 1.5, 0.5), Vector3(1, zero, zero)}));
    }
}

TEST(Aabb, GrazingRaysOnFacesAndEdgesAreNeverCulled) {
    // Origin exactly on a slab plane with a zero direction component (0 * inf = NaN) and rays
    // that run along a face or an edge: all touch the closed box, so all must hit.
    EXPECT_TRUE(kUnitBox.intersect(Ray{Point3(-1, 1, 0.5), Vector3(1, 0, 0)}));
    EXPECT_TRUE(kUnitBox.intersect(Ray{Point3(-1, 0, 0), Vector3(1, 0, 0)}));
    EXPECT_TRUE(kUnitBox.intersect(Ray{Point3(-1, 1, 1), Vector3(1, 0, 0)}));
    EXPECT_TRUE(kUnitBox.intersect(Ray{Point3(0, 0, -5), Vector3(0, 0, 1)}));
}

TEST(Aabb, RaysThroughTheBoxFromRandomPointsAlwaysHit) {
    // Independent answer: a ray aimed at a point strictly inside the box must hit it, however
    // far away it starts. 100,000 seeded rays at scales from 1e-6 to 1e6.
    test::Random random(7);
    for (int i = 0; i < 100000; ++i) {
        const double scale = std::pow(10.0, random.uniform(-6, 6));
        const Aabb box(Point3(-scale, -scale, -scale) * random.uniform(0.1, 1),
                       Point3(scale, scale, scale) * random.uniform(0.1, 1));
        const Point3 target = random.in_box(box);
        const Point3 origin = target + random.unit_vector() * scale * random.uniform(0, 1e6);
        const Ray ray{origin, target - origin};
        ASSERT_TRUE(box.intersect(ray)) << "ray " << i;
    }
}

}  // namespace
}  // namespace csgrt
