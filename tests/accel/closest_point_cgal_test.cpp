#include "csgrt/accel/closest_point.h"

#include <gtest/gtest.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <limits>
#include <vector>

#include "support/meshes.h"
#include "support/precisions.h"
#include "support/random.h"
#include "support/rays.h"

namespace csgrt {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalTriangles = std::vector<Kernel::Triangle_3>;
using CgalPrimitive = CGAL::AABB_triangle_primitive<Kernel, CgalTriangles::const_iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CgalPrimitive>>;

template <class Real>
TriangleSet<Real> set_of(const test::TestMesh& mesh) {
    return TriangleSet<Real>(mesh.vertices, mesh.triangles);
}

// The answer of the loop over every triangle, with the tree's tie rule (lower index wins).
template <class Real>
ClosestPoint brute_force_closest(const TriangleSet<Real>& set, const Point3& p) {
    ClosestPoint best;
    for (std::size_t i = 0; i < set.size(); ++i) {
        double u, v;
        const Point3 q = closest_point_on_triangle(p, set.corner(i, 0).template cast<double>(),
                                                   set.corner(i, 1).template cast<double>(),
                                                   set.corner(i, 2).template cast<double>(), u, v);
        const double d2 = (p - q).squaredNorm();
        if (d2 < best.squared_distance) {
            best = ClosestPoint{q, d2, static_cast<std::uint32_t>(i), u, v};
        }
    }
    return best;
}

TEST(ClosestPointOnTriangle, EveryVoronoiRegionAgainstTheClosedForm) {
    // The unit right triangle in z = 0: the nearest point of (x, y, h) is the planar nearest
    // point of (x, y) in the triangle, worked out by hand for each region.
    const Point3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
    struct Case {
        Point3 p, expected;
    };
    const Case cases[] = {
        {{0.25, 0.25, 2.0}, {0.25, 0.25, 0.0}},  // face
        {{-1.0, -1.0, 0.5}, {0.0, 0.0, 0.0}},    // corner a
        {{3.0, -1.0, 0.0}, {1.0, 0.0, 0.0}},     // corner b
        {{-0.5, 4.0, 1.0}, {0.0, 1.0, 0.0}},     // corner c
        {{0.5, -2.0, 1.0}, {0.5, 0.0, 0.0}},     // edge ab
        {{-3.0, 0.25, 0.0}, {0.0, 0.25, 0.0}},   // edge ac
        {{1.0, 1.0, -1.0}, {0.5, 0.5, 0.0}},     // edge bc
    };
    for (const Case& test : cases) {
        double u, v;
        const Point3 q = closest_point_on_triangle(test.p, a, b, c, u, v);
        // Each coordinate is formed by a handful of operations on values below 5: a few ulps.
        EXPECT_NEAR((q - test.expected).norm(), 0.0, 1e-15) << test.p.transpose();
        EXPECT_NEAR((a + u * (b - a) + v * (c - a) - q).norm(), 0.0, 1e-15);
    }
    // A degenerate (collinear) triangle: the nearest point of its longest edge.
    double u, v;
    const Point3 q = closest_point_on_triangle(Point3(0.5, 1, 0), a, b, Point3(2, 0, 0), u, v);
    EXPECT_EQ(q, Point3(0.5, 0, 0));
}

template <class Real>
class ClosestPointTreeTest : public ::testing::Test {};
TYPED_TEST_SUITE(ClosestPointTreeTest, test::Precisions);

TYPED_TEST(ClosestPointTreeTest, BitsOfBruteForceAndDistanceOfCgal) {
    using Real = TypeParam;
    const test::TestMesh mesh = test::sphere_mesh(4);  // 2,048 triangles
    const TriangleSet<Real> set = set_of<Real>(mesh);
    const ClosestPointTree<Real> tree(set);

    CgalTriangles triangles;
    for (std::size_t i = 0; i < set.size(); ++i) {
        auto point = [&](int k) {
            const auto& c = set.corner(i, k);
            return Kernel::Point_3(double(c.x()), double(c.y()), double(c.z()));
        };
        triangles.emplace_back(point(0), point(1), point(2));
    }
    CgalTree cgal(triangles.begin(), triangles.end());
    cgal.accelerate_distance_queries();

    test::Random random(71);
    const Aabb around = test::enlarged(test::mesh_bounds(mesh), 1.0);
    for (int i = 0; i < 2000; ++i) {
        // Half the points near the surface (where neighbouring triangles compete), half anywhere.
        const Point3 p = i % 2 ? random.in_box(around)
                               : Point3(random.unit_vector() * random.uniform(0.97, 1.03));
        const ClosestPoint answer = tree.closest(p);
        const ClosestPoint brute = brute_force_closest(set, p);
        // The tree only prunes the loop: the same triangle, and the same bits.
        ASSERT_EQ(answer.primitive, brute.primitive) << i;
        ASSERT_EQ(answer.point, brute.point) << i;
        ASSERT_EQ(answer.squared_distance, brute.squared_distance) << i;

        const Kernel::Point_3 query(p.x(), p.y(), p.z());
        const Kernel::Point_3 reference = cgal.closest_point(query);
        const double cgal_distance = std::sqrt(CGAL::to_double(cgal.squared_distance(query)));
        // Both sides project p in double with a few dozen operations on coordinates below 3:
        // each distance is within ~1e-15 of the true one; 1e-13 leaves room for the different
        // operation orders and is far below the 1e-3 gap between neighbouring triangles' answers.
        EXPECT_NEAR(std::sqrt(answer.squared_distance), cgal_distance, 1e-13) << i;
        EXPECT_NEAR((answer.point - Point3(reference.x(), reference.y(), reference.z())).norm(),
                    0.0, 1e-6)
            << i;  // the point itself may differ along a tie, but only that far on this mesh
    }
}

TYPED_TEST(ClosestPointTreeTest, TiesGoToTheLowerIndexAndEdgesAreExact) {
    using Real = TypeParam;
    // The cube [0, 2]^3 in 2 x 2 squares a face: integer corners, exact in float.
    const test::TestMesh mesh = test::integer_cube(2);
    const TriangleSet<Real> set = set_of<Real>(mesh);
    const ClosestPointTree<Real> tree(set);
    test::Random random(5);
    for (int i = 0; i < 500; ++i) {
        // Points on lattice positions: many are equidistant to several triangles.
        const Point3 p(random.integer(-2, 4) * 0.5, random.integer(-2, 4) * 0.5,
                       random.integer(-2, 4) * 0.5);
        const ClosestPoint answer = tree.closest(p);
        const ClosestPoint brute = brute_force_closest(set, p);
        ASSERT_EQ(answer.primitive, brute.primitive) << p.transpose();
        ASSERT_EQ(answer.squared_distance, brute.squared_distance) << p.transpose();
        // Distance to the cube's surface in closed form: outside, the distance to the box;
        // inside, the distance to the nearest face.
        const Vector3 outside = (-p).cwiseMax(0.0) + (p - Point3(2, 2, 2)).cwiseMax(0.0);
        const double inside = std::min({p.x(), p.y(), p.z(), 2 - p.x(), 2 - p.y(), 2 - p.z()});
        const double expected = outside.squaredNorm() > 0 ? outside.norm() : inside;
        // Lattice points and integer corners: a few roundings at most in the projection.
        EXPECT_NEAR(std::sqrt(answer.squared_distance), expected, 1e-15) << p.transpose();
    }
}

TYPED_TEST(ClosestPointTreeTest, EmptySetOneTriangleAndNonFinitePoints) {
    using Real = TypeParam;
    const TriangleSet<Real> empty;
    const ClosestPointTree<Real> none(empty);
    EXPECT_EQ(none.closest(Point3(0, 0, 0)).primitive, kNoIndex);
    EXPECT_EQ(none.closest(Point3(0, 0, 0)).squared_distance, kInfinity);

    test::TestMesh one;
    one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    one.triangles = {{0, 1, 2}};
    const TriangleSet<Real> set = set_of<Real>(one);
    const ClosestPointTree<Real> tree(set);
    const ClosestPoint answer = tree.closest(Point3(0.25, 0.25, 3));
    EXPECT_EQ(answer.primitive, 0u);
    EXPECT_EQ(answer.squared_distance, 9.0);
    EXPECT_DOUBLE_EQ(answer.u, 0.25);
    EXPECT_DOUBLE_EQ(answer.v, 0.25);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(tree.closest(Point3(nan, 0, 0)).primitive, kNoIndex);
    EXPECT_EQ(tree.closest(Point3(kInfinity, 0, 0)).primitive, kNoIndex);
}

}  // namespace
}  // namespace csgrt
