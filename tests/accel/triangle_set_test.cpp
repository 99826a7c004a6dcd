#include "csgrt/accel/triangle_set.h"

#include <gtest/gtest.h>

#include "accel/grid_test_common.h"
#include "csgrt/accel/brute_force.h"
#include "support/meshes.h"
#include "support/precisions.h"
#include "support/random.h"

namespace csgrt {
namespace {

template <class Real>
class TriangleSetTest : public ::testing::Test {};
TYPED_TEST_SUITE(TriangleSetTest, test::Precisions);

TYPED_TEST(TriangleSetTest, AnalyticHitWithBarycentrics) {
    const std::vector<Eigen::Vector3d> vertices = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
    const TriangleSet<TypeParam> set(vertices, triangles);
    QueryScratch scratch;
    const Ray ray{Point3(1, 2, 5), Vector3(0, 0, -2)};
    HitRecord record;
    record.t = ray.t_max;
    ASSERT_TRUE(set.intersect(0, set.prepare(ray, scratch), record));
    EXPECT_DOUBLE_EQ(record.t, 2.5);
    EXPECT_FLOAT_EQ(record.u, 0.25f);  // weight of corner 1: x / 4
    EXPECT_FLOAT_EQ(record.v, 0.5f);   // weight of corner 2: y / 4
    EXPECT_EQ(record.primitive, 0u);
    // The interval is closed at both ends and honoured at both.
    for (auto [t_min, t_max, expected] : {std::tuple{0.0, 2.5, true},
                                          {2.5, 9.0, true},
                                          {0.0, 2.4999, false},
                                          {2.5001, 9.0, false}}) {
        const Ray clipped{ray.origin, ray.direction, t_min, t_max};
        EXPECT_EQ(set.occluded(0, set.prepare(clipped, scratch)), expected)
            << t_min << " " << t_max;
    }
    EXPECT_FALSE(set.occluded(0, set.prepare(Ray{Point3(3, 3, 5), Vector3(0, 0, -1)}, scratch)));
}

TYPED_TEST(TriangleSetTest, TiesGoToTheLowerIndexWhateverTheOrder) {
    const std::vector<Eigen::Vector3d> vertices = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}, {0, 1, 2}, {1, 2, 0}};
    const TriangleSet<TypeParam> set(vertices, triangles);
    QueryScratch scratch;
    const Ray ray{Point3(1, 1, 5), Vector3(0, 0, -1)};
    const auto prepared = set.prepare(ray, scratch);
    for (std::array<int, 3> order : {std::array{0, 1, 2}, {2, 1, 0}, {1, 2, 0}}) {
        HitRecord record;
        record.t = ray.t_max;
        for (int i : order) set.intersect(i, prepared, record);
        EXPECT_EQ(record.primitive, 0u);
    }
}

TYPED_TEST(TriangleSetTest, ClosedMeshNeverLeaksAtSharedEdgesAndVertices) {
    // Watertightness (Woop et al. 2013): from a point inside a closed mesh every ray must hit
    // it, including rays aimed exactly at shared vertices and edge midpoints, where a
    // non-watertight test lets rays slip between neighbours.
    const test::TestMesh cube = test::integer_cube(8);
    const test::BruteForceMesh<TypeParam> oracle(cube);
    const auto& brute = oracle.brute;
    QueryScratch scratch;
    test::Random random(41);
    int rays = 0;
    auto expect_hit = [&](const Point3& origin, const Vector3& direction) {
        ++rays;
        HitRecord record;
        EXPECT_TRUE(brute.intersect(Ray{origin, direction}, record, scratch))
            << "leak from (" << origin.transpose() << ") along (" << direction.transpose() << ")";
    };
    const std::vector<Point3> origins = {Point3(4, 4, 4), Point3(1, 2, 3), Point3(0.5, 7.5, 4)};
    for (const Point3& origin : origins) {
        for (const Eigen::Vector3d& vertex : cube.vertices) expect_hit(origin, vertex - origin);
        for (const auto& triangle : cube.triangles) {
            for (int k = 0; k < 3; ++k) {
                const Point3 midpoint =
                    0.5 * (cube.vertices[triangle[k]] + cube.vertices[triangle[(k + 1) % 3]]);
                expect_hit(origin, midpoint - origin);
            }
        }
    }
    for (int i = 0; i < 100000; ++i) {
        const Point3 origin =
            random.in_box(Aabb(Point3(0.01, 0.01, 0.01), Point3(7.99, 7.99, 7.99)));
        expect_hit(origin, random.unit_vector());
    }
    EXPECT_GT(rays, 100000);
}

TYPED_TEST(TriangleSetTest, SphereMeshFromInsideNeverLeaks) {
    const test::TestMesh sphere = test::sphere_mesh(4);
    const test::BruteForceMesh<TypeParam> oracle(sphere);
    const auto& brute = oracle.brute;
    QueryScratch scratch;
    test::Random random(42);
    for (int i = 0; i < 20000; ++i) {
        const Point3 origin = random.unit_vector() * random.uniform(0, 0.9);
        HitRecord record;
        ASSERT_TRUE(brute.intersect(Ray{origin, random.unit_vector()}, record, scratch)) << i;
        // Every vertex aimed at exactly.
        const Eigen::Vector3d& vertex = sphere.vertices[i % sphere.vertices.size()];
        ASSERT_TRUE(brute.intersect(Ray{origin, vertex - origin}, record, scratch)) << i;
    }
}

TEST(BruteForce, BoxCullingGivesTheSameAnswers) {
    const test::TestMesh sphere = test::sphere_mesh(3);
    const TriangleSet<float> set(sphere.vertices, sphere.triangles);
    BruteForce<TriangleSet<float>> plain, culled;
    plain.build(set);
    culled.build(set, BruteForceConfig{.box_culling = true});
    QueryScratch scratch;
    test::Random random(43);
    TraversalCounters plain_counts, culled_counts;
    for (int i = 0; i < 20000; ++i) {
        const Ray ray = random.ray_between(Aabb(Point3(-3, -3, -3), Point3(3, 3, 3)),
                                           Aabb(Point3(-1, -1, -1), Point3(1, 1, 1)));
        HitRecord a, b;
        const bool hit_a = plain.intersect_counted(ray, a, scratch, plain_counts);
        const bool hit_b = culled.intersect_counted(ray, b, scratch, culled_counts);
        ASSERT_EQ(hit_a, hit_b) << i;
        if (hit_a) {
            EXPECT_EQ(a.primitive, b.primitive) << i;
            EXPECT_EQ(a.t, b.t) << i;
        }
        EXPECT_EQ(plain.occluded(ray, scratch), hit_a) << i;
        EXPECT_EQ(culled.occluded(ray, scratch), hit_a) << i;
    }
    // Boxes cull most primitive tests for a mesh of small triangles.
    EXPECT_LT(culled_counts.primitives_tested * 5, plain_counts.primitives_tested);
}

}  // namespace
}  // namespace csgrt
