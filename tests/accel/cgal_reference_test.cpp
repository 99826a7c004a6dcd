#include "csgrt/reference/cgal_reference.h"

#include <gtest/gtest.h>

#include "csgrt/accel/brute_force.h"
#include "support/meshes.h"
#include "support/precisions.h"
#include "support/random.h"
#include "support/reference_check.h"

namespace csgrt {
namespace {

TEST(CgalReference, AnalyticTriangle) {
    const std::vector<Eigen::Vector3d> vertices = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
    const TriangleSet<double> set(vertices, triangles);
    const CgalReference reference(set);
    const Ray ray{Point3(1, 1, 5), Vector3(0, 0, -2)};
    ASSERT_TRUE(reference.do_intersect(ray));
    const auto nearest = reference.nearest(ray);
    ASSERT_TRUE(nearest);
    EXPECT_EQ(nearest->t, 2.5);
    EXPECT_EQ(nearest->primitive, 0u);
    // Exactly on the hypotenuse x + y = 4: exact predicates say it touches.
    EXPECT_TRUE(reference.do_intersect(Ray{Point3(2, 2, 5), Vector3(0, 0, -1)}));
    EXPECT_FALSE(reference.do_intersect(Ray{Point3(2, 2.0000001, 5), Vector3(0, 0, -1)}));
    // A bounded interval is a segment.
    EXPECT_FALSE(reference.do_intersect(Ray{Point3(1, 1, 5), Vector3(0, 0, -1), 0.0, 4.9}));
    EXPECT_TRUE(reference.do_intersect(Ray{Point3(1, 1, 5), Vector3(0, 0, -1), 0.0, 5.0}));
}

template <class Real>
class ReferenceAgreement : public ::testing::Test {};
TYPED_TEST_SUITE(ReferenceAgreement, test::Precisions);

TYPED_TEST(ReferenceAgreement, BruteForceAgreesWithExactPredicates) {
    // The watertight test against CGAL's exact predicates on a closed sphere mesh and on an
    // integer cube whose shared edges and vertices are hit on purpose; the tolerances are the
    // ambiguity band of support/reference_check.h (64 roundoffs of Real, stretched by the
    // incidence angle).
    test::Random random(51);
    for (const test::TestMesh& mesh : {test::sphere_mesh(4), test::integer_cube(6)}) {
        const TriangleSet<TypeParam> set(mesh.vertices, mesh.triangles);
        const CgalReference reference(set);
        BruteForce<TriangleSet<TypeParam>> brute;
        brute.build(set);
        Aabb box;
        for (const auto& v : mesh.vertices) box.extend(v);
        QueryScratch scratch;
        test::ReferenceTally tally;
        for (int i = 0; i < 20000; ++i) {
            Ray ray = random.ray_between(test::enlarged(box, 1.0), box);
            if (i % 4 == 0) {  // aim exactly at a vertex
                ray.direction = mesh.vertices[i % mesh.vertices.size()] - ray.origin;
            }
            test::compare_with_reference(brute, set, reference, ray, scratch, tally);
        }
        tally.print(std::string("brute ") + (sizeof(TypeParam) == 4 ? "float" : "double"));
        EXPECT_EQ(tally.disagreements(), 0);
        EXPECT_GT(tally.hits, 10000);
        // Rays aimed exactly at vertices are the ambiguous ones; they must stay a minority.
        EXPECT_LT(tally.ambiguous, tally.rays / 4);
    }
}

}  // namespace
}  // namespace csgrt
