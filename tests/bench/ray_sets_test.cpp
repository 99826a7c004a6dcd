#include "csgrt/bench/ray_sets.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "csgrt/accel/brute_force.h"
#include "csgrt/accel/triangle_set.h"
#include "support/meshes.h"

namespace csgrt::bench {
namespace {

const Aabb kBox(Point3(-1, 2, 3), Point3(4, 5, 7));

TEST(SplitMix, SameSeedSameNumbersInRange) {
    SplitMix a(42), b(42), c(43);
    bool differs = false;
    for (int i = 0; i < 1000; ++i) {
        const double x = a.uniform();
        EXPECT_EQ(x, b.uniform());
        EXPECT_GE(x, 0.0);
        EXPECT_LT(x, 1.0);
        differs |= x != c.uniform();
        EXPECT_NEAR(a.unit_vector().norm(), 1.0, 1e-15);
        b.unit_vector();
        c.unit_vector();
    }
    EXPECT_TRUE(differs);
}

TEST(CameraRays, OneUnitRayPerPixelFromTheCamera) {
    const Camera camera = framing_camera(kBox);
    EXPECT_FALSE(kBox.contains(camera.position));
    const RaySet set = camera_rays(camera, 33, 17);
    ASSERT_EQ(set.rays.size(), 33u * 17u);
    EXPECT_EQ(set.width, 33);
    EXPECT_EQ(set.height, 17);
    for (const Ray& ray : set.rays) {
        EXPECT_EQ(ray.origin, camera.position);
        EXPECT_NEAR(ray.direction.norm(), 1.0, 1e-15);
        EXPECT_TRUE(is_valid(ray));
    }
    // The middle pixel of an odd-sized image looks straight at the box's centre.
    const Ray& middle = set.rays[8 * 33 + 16];
    const Vector3 toward = (kBox.center() - camera.position).normalized();
    EXPECT_NEAR(middle.direction.dot(toward), 1.0, 1e-14);
    // Corner pixels look away from the centre, up-left first (row-major, y down).
    EXPECT_GT(set.rays.front().direction.y(), middle.direction.y());
}

TEST(CameraRays, TheBoxFillsMuchOfTheImage) {
    // The box's largest extent spans the view's height: a good share of the rays hit the box.
    const RaySet set = camera_rays(framing_camera(kBox), 64, 64);
    int hits = 0;
    for (const Ray& ray : set.rays) hits += kBox.intersect(ray) ? 1 : 0;
    EXPECT_GT(hits, 64 * 64 / 4);
    EXPECT_LT(hits, 64 * 64);
}

TEST(IncoherentRays, FromTheSphereAroundTheBoxIntoIt) {
    const RaySet set = incoherent_rays(kBox, 5000, 9);
    ASSERT_EQ(set.rays.size(), 5000u);
    const double radius = 0.75 * kBox.diagonal().norm();
    for (const Ray& ray : set.rays) {
        EXPECT_NEAR((ray.origin - kBox.center()).norm(), radius, 1e-12 * radius);
        EXPECT_FALSE(kBox.contains(ray.origin));
        EXPECT_NEAR(ray.direction.norm(), 1.0, 1e-15);
        // Aimed at a point inside the box, so every ray enters it.
        EXPECT_TRUE(kBox.intersect(ray));
    }
    // Fixed by the seed.
    const RaySet again = incoherent_rays(kBox, 5000, 9);
    EXPECT_EQ(again.rays.back().origin, set.rays.back().origin);
    EXPECT_NE(incoherent_rays(kBox, 1, 10).rays[0].origin, set.rays[0].origin);
}

TEST(ShadowRays, FromTheLitSideTowardTheLight) {
    // Primary rays straight down onto the plane z = 0 (normal +z), and one arriving from
    // below, whose lit side is the other one.
    const std::vector<Ray> primary = {
        Ray{Point3(0, 0, 5), Vector3(0, 0, -1)}, Ray{Point3(1, 0, 5), Vector3(0, 0, -2)},
        Ray{Point3(2, 0, -5), Vector3(0, 0, 1)}, Ray{Point3(3, 0, 5), Vector3(0, 0, -1)}};
    const std::vector<SurfaceHit> hits = {{true, 5.0, Vector3(0, 0, 1)},
                                          {true, 2.5, Vector3(0, 0, 1)},
                                          {true, 5.0, Vector3(0, 0, 1)},
                                          {false, 0.0, Vector3(0, 0, 1)}};
    const Point3 light(0, 0, 10);
    const RaySet set = shadow_rays(primary, hits, light, 1e-3);
    // The ray from below sees the unlit side: no shadow ray; the miss has none either.
    ASSERT_EQ(set.rays.size(), 2u);
    EXPECT_TRUE(set.rays[0].origin.isApprox(Point3(0, 0, 1e-3)));
    EXPECT_TRUE(set.rays[1].origin.isApprox(Point3(1, 0, 1e-3)));
    for (const Ray& ray : set.rays) {
        EXPECT_EQ(ray.t_min, 0.0);
        EXPECT_EQ(ray.t_max, 1.0);
        EXPECT_TRUE(ray.at(1.0).isApprox(light));
    }
    // A light below the plane lights the side the third ray came from.
    EXPECT_EQ(shadow_rays(primary, hits, Point3(0, 0, -10), 1e-3).rays.size(), 1u);
}

TEST(ShadowRays, NothingOnAConvexMeshShadowsItself) {
    // On a convex closed mesh a lit point sees the light unobstructed, so every shadow ray
    // must be unoccluded: the offset keeps it off its own triangle and N.L > 0 keeps it out of
    // the mesh. (Offset 1e-5 of the diagonal against float rounding of ~1e-7.)
    const test::TestMesh mesh = test::sphere_mesh(3);
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    BruteForce<TriangleSet<float>> brute;
    brute.build(set);
    const Aabb box(Point3(-1, -1, -1), Point3(1, 1, 1));
    const RaySet primary = camera_rays(framing_camera(box), 48, 48);
    std::vector<SurfaceHit> hits;
    QueryScratch scratch;
    for (const Ray& ray : primary.rays) {
        HitRecord record;
        SurfaceHit hit;
        if (brute.intersect(ray, record, scratch)) {
            const Vector3 a = set.corner(record.primitive, 0).cast<double>();
            const Vector3 b = set.corner(record.primitive, 1).cast<double>();
            const Vector3 c = set.corner(record.primitive, 2).cast<double>();
            hit = {true, record.t, (b - a).cross(c - a).normalized()};
        }
        hits.push_back(hit);
    }
    const RaySet shadows =
        shadow_rays(primary.rays, hits, default_light(box), 1e-5 * box.diagonal().norm());
    ASSERT_GT(shadows.rays.size(), 200u);
    int occluded = 0;
    for (const Ray& ray : shadows.rays) occluded += brute.occluded(ray, scratch) ? 1 : 0;
    EXPECT_EQ(occluded, 0);
}

TEST(SpreadSubset, EvenlyOverTheWholeList) {
    std::vector<Ray> rays(1000);
    for (std::size_t i = 0; i < rays.size(); ++i) rays[i].t_max = static_cast<double>(i);
    const std::vector<Ray> subset = spread_subset(rays, 10);
    ASSERT_EQ(subset.size(), 10u);
    for (std::size_t k = 0; k < subset.size(); ++k) EXPECT_EQ(subset[k].t_max, 100.0 * k);
    EXPECT_EQ(spread_subset(rays, 5000).size(), 1000u);
}

}  // namespace
}  // namespace csgrt::bench
