// The regular and the hierarchical grid against brute force on in-code meshes and on 10,000
// spheres, at their default settings. Both are checked on the same rays, so each ray's brute
// force answer (the expensive part) is computed once.

#include <gtest/gtest.h>

#include "accel/grid_test_common.h"
#include "csgrt/accel/hierarchical_grid.h"
#include "csgrt/accel/regular_grid.h"
#include "support/precisions.h"

namespace csgrt {
namespace {

using test::TestMesh;

template <class Real>
class GridAgreementTest : public ::testing::Test {
protected:
    /// Builds both grids and brute force over `mesh` and checks the grids against brute force
    /// on camera-like, incoherent and axis-parallel rays; returns how many rays were checked.
    int expect_agreement_on(const TestMesh& mesh, int camera, int incoherent, std::uint64_t seed,
                            const GridConfig& grid_config = {},
                            const HierarchicalGridConfig& hgrid_config = {}) {
        const TriangleSet<Real> set(mesh.vertices, mesh.triangles);
        RegularGrid<TriangleSet<Real>> grid;
        grid.build(set, grid_config);
        HierarchicalGrid<TriangleSet<Real>> hgrid;
        hgrid.build(set, hgrid_config);
        BruteForce<TriangleSet<Real>> brute;
        brute.build(set);
        const test::AgreementCounts counts = test::expect_agreement(
            {&grid, &hgrid}, brute,
            test::agreement_rays(test::mesh_bounds(mesh), camera, incoherent, seed), 16);
        // Every mesh here is hit by a good share of these rays; a structure that missed
        // everything would agree with nothing.
        EXPECT_GT(counts.hits, counts.rays / 5)
            << grid.stats().details << "; " << hgrid.stats().details;
        return counts.rays;
    }
};
TYPED_TEST_SUITE(GridAgreementTest, test::Precisions);

// Together these check 112,350 rays per precision against brute force, for each grid.
TYPED_TEST(GridAgreementTest, IntegerCube) {
    // Vertices, edges and faces on integer planes: rays meet shared edges and vertices.
    EXPECT_EQ(this->expect_agreement_on(test::integer_cube(8), 24500, 24500, 101), 51450);
}

TYPED_TEST(GridAgreementTest, SphereMesh) {
    // 8,192 triangles: each brute-force answer is costly, so fewer rays here (the real meshes
    // of structure_reference_test.cpp, up to 52,000 triangles, are compared with brute force
    // and CGAL there).
    EXPECT_EQ(this->expect_agreement_on(test::sphere_mesh(5), 3000, 3000, 102), 6300);
}

TYPED_TEST(GridAgreementTest, LongThinTriangles) {
    // With and without the triangle-box test: both must find exactly what brute force finds.
    const TestMesh soup = test::long_thin_soup(2000, 7);
    EXPECT_EQ(this->expect_agreement_on(soup, 6000, 6000, 104), 12600);
    EXPECT_EQ(
        this->expect_agreement_on(soup, 2000, 2000, 105, GridConfig{.triangle_box_test = false},
                                  HierarchicalGridConfig{.triangle_box_test = false}),
        4200);
}

TYPED_TEST(GridAgreementTest, TeapotInStadium) {
    EXPECT_EQ(this->expect_agreement_on(test::teapot_in_stadium(), 10000, 10000, 106), 21000);
}

TYPED_TEST(GridAgreementTest, FarFromTheOrigin) {
    // A mesh of unit size at coordinates near 1000: float rounds the ray origin by up to
    // 3e-5 there, so the float test answers for a slightly shifted ray and may report hits
    // just outside a triangle's box. The cells' padding (relative to the coordinates) must
    // cover that at every level, or a hit brute force finds lies in a cell that does not
    // list its triangle.
    TestMesh far;
    test::append(far, test::sphere_mesh(4), 1.0, Vector3(1000.3, -1000.7, 999.1));
    test::append(far, test::long_thin_soup(300, 5), 0.2, Vector3(999.0, -1001.0, 998.0));
    EXPECT_EQ(this->expect_agreement_on(far, 8000, 8000, 111), 16800);
}

TEST(GridAgreement, TenThousandSpheres) {
    const ShapeSet set(test::random_spheres(10000, 16));
    RegularGrid<ShapeSet> grid;
    grid.build(set);
    HierarchicalGrid<ShapeSet> hgrid;
    hgrid.build(set);
    BruteForce<ShapeSet> brute;
    brute.build(set);
    const Aabb box(Point3(0, 0, 0), Point3(10, 10, 10));
    std::vector<Ray> rays = test::camera_rays(box, 2000, 17);
    const std::vector<Ray> more = test::incoherent_rays(box, 2000, 18);
    rays.insert(rays.end(), more.begin(), more.end());
    const test::AgreementCounts counts = test::expect_agreement({&grid, &hgrid}, brute, rays, 10);
    EXPECT_GT(counts.hits, counts.rays / 4);
    test::expect_same_answers_concurrently(grid, rays, 3);
    test::expect_same_answers_concurrently(hgrid, rays, 3);
}

}  // namespace
}  // namespace csgrt
