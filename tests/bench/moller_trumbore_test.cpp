#include "csgrt/bench/moller_trumbore.h"

#include <gtest/gtest.h>

#include "csgrt/accel/triangle_set.h"
#include "support/precisions.h"
#include "support/random.h"

namespace csgrt::bench {
namespace {

TEST(MollerTrumbore, AnalyticHit) {
    using Test = MollerTrumbore<double>;
    const Eigen::Vector3d a(0, 0, 0), b(4, 0, 0), c(0, 4, 0);
    double t, u, v;
    ASSERT_TRUE(
        Test::hit(a, b, c, Test::prepare(Ray{Point3(1, 2, 5), Vector3(0, 0, -2)}), t, u, v));
    EXPECT_EQ(t, 2.5);
    EXPECT_EQ(u, 0.25);
    EXPECT_EQ(v, 0.5);
    // Outside, behind the origin, beyond t_max.
    EXPECT_FALSE(
        Test::hit(a, b, c, Test::prepare(Ray{Point3(3, 3, 5), Vector3(0, 0, -1)}), t, u, v));
    EXPECT_FALSE(
        Test::hit(a, b, c, Test::prepare(Ray{Point3(1, 1, 5), Vector3(0, 0, 1)}), t, u, v));
    EXPECT_FALSE(Test::hit(a, b, c, Test::prepare(Ray{Point3(1, 1, 5), Vector3(0, 0, -1), 0, 4.9}),
                           t, u, v));
}

template <class Real>
class MollerTrumboreAgreement : public ::testing::Test {};
TYPED_TEST_SUITE(MollerTrumboreAgreement, test::Precisions);

TYPED_TEST(MollerTrumboreAgreement, SameAnswersAsWatertightAwayFromEdges) {
    // Rays through random points of random triangles, at least 1% of the triangle's size from
    // its edges, with t = 1 exactly at the point: both tests must hit, and each t must be 1 to
    // within the a-priori bound of its precision; rays through points 1% outside must miss in
    // both. Moeller-Trumbore's t = e2.(s x e1) / e1.(d x e2): each triple product is a cross
    // and a dot of Real inputs (rounded from double), so its absolute error is at most about
    // 8 eps times the product of the norms (3 rounded inputs, 2 roundings in the cross, 3 in
    // the dot); relative to det = t e1.(d x e2) both errors add up to
    // 16 eps (|s| + |d|) |e1| |e2| / |det|.
    using Real = TypeParam;
    using Test = MollerTrumbore<Real>;
    test::Random random(3);
    const double epsilon = std::numeric_limits<Real>::epsilon();
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Aabb box(Point3(-1, -1, -1), Point3(1, 1, 1));
        const std::vector<Eigen::Vector3d> vertices = {random.in_box(box), random.in_box(box),
                                                       random.in_box(box)};
        const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
        const TriangleSet<Real> set(vertices, triangles);
        const auto corner = [&](int k) { return set.corner(0, k); };
        const Eigen::Vector3d a = corner(0).template cast<double>(),
                              b = corner(1).template cast<double>(),
                              c = corner(2).template cast<double>();
        if ((b - a).cross(c - a).norm() < 0.05) continue;  // skip slivers: far from "away"
        double w1 = random.uniform(0.01, 0.98), w2 = random.uniform(0.01, 0.99 - w1);
        const bool inside = i % 2 == 0;
        if (!inside) w1 = -0.01 - w1 * 0.5;  // outside the edge opposite corner 1
        const Point3 target = a + w1 * (b - a) + w2 * (c - a);
        Ray ray;
        ray.origin = target + 3.0 * random.unit_vector();
        ray.direction = target - ray.origin;
        // A ray nearly in the triangle's plane is the published test's blind spot (|det| <
        // 1e-6 is rejected): only compare rays that cross it at a reasonable angle.
        const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
        if (std::abs(normal.dot(ray.direction.normalized())) < 0.05) continue;
        QueryScratch scratch;
        HitRecord record;
        record.t = ray.t_max;
        const bool watertight = set.intersect(0, set.prepare(ray, scratch), record);
        double t, u, v;
        const bool moller = Test::hit(corner(0), corner(1), corner(2), Test::prepare(ray), t, u, v);
        ASSERT_EQ(watertight, moller) << "ray " << i;
        EXPECT_EQ(watertight, inside);
        if (watertight) {
            ++hits;
            const double determinant = std::abs((b - a).dot(ray.direction.cross(c - a)));
            const double bound = 16.0 * epsilon * ((ray.origin - a).norm() + ray.direction.norm()) *
                                 (b - a).norm() * (c - a).norm() / determinant;
            EXPECT_NEAR(t, 1.0, bound) << "ray " << i;
            EXPECT_NEAR(record.t, 1.0, bound) << "ray " << i;
        }
    }
    EXPECT_GT(hits, 5000);
}

TEST(MollerTrumbore, ThePublishedEpsilonRejectsSmallTriangles) {
    // A triangle of side 1e-4 hit head-on: det = |e1 x e2| |d| = 1e-8 < 1e-6, so the published
    // test rejects it while the watertight test, which has no epsilon, hits it.
    const std::vector<Eigen::Vector3d> vertices = {{0, 0, 0}, {1e-4, 0, 0}, {0, 1e-4, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
    const TriangleSet<double> set(vertices, triangles);
    const Ray ray{Point3(2e-5, 2e-5, 1), Vector3(0, 0, -1)};
    QueryScratch scratch;
    HitRecord record;
    record.t = ray.t_max;
    EXPECT_TRUE(set.intersect(0, set.prepare(ray, scratch), record));
    double t, u, v;
    using Test = MollerTrumbore<double>;
    EXPECT_FALSE(Test::hit(vertices[0], vertices[1], vertices[2], Test::prepare(ray), t, u, v));
}

}  // namespace
}  // namespace csgrt::bench
