#include "csgrt/accel/hierarchical_grid.h"

#include <gtest/gtest.h>

#include "accel/grid_test_common.h"
#include "csgrt/core/error.h"
#include "support/precisions.h"

namespace csgrt {
namespace {

using test::TestMesh;

/// A top grid of about one cell per primitive, so the few-triangle scenes of the rounding
/// cases get cell boundaries next to their triangles.
const HierarchicalGridConfig kFineTop{.top_cells_exponent = 1.0};

/// The top grid the hierarchy builds over `mesh` with kFineTop.
template <class Real>
detail::GridGeometry top_geometry(const TestMesh& mesh) {
    return test::BuiltMesh<Real, HierarchicalGrid>(mesh, kFineTop).structure.geometry(0);
}

template <class Real>
class HierarchicalGridTest : public ::testing::Test {};
TYPED_TEST_SUITE(HierarchicalGridTest, test::Precisions);

// The agreement on in-code meshes at the default settings is in grid_agreement_test.cpp.
TYPED_TEST(HierarchicalGridTest, AgreesWithBruteForceUnderOtherSettings) {
    // No nesting (a plain coarse grid), deep nesting with small cells, one cell on top, and
    // sub-grids forced wherever a cell holds more than one primitive.
    const TestMesh mesh = test::teapot_in_stadium();
    test::expect_agreement_on_mesh<TypeParam, HierarchicalGrid>(
        mesh, 2000, 2000, 208, HierarchicalGridConfig{.max_depth = 0});
    test::expect_agreement_on_mesh<TypeParam, HierarchicalGrid>(
        mesh, 2000, 2000, 209,
        HierarchicalGridConfig{
            .max_primitives_per_cell = 1, .sub_cells_per_primitive = 16, .max_depth = 6});
    test::expect_agreement_on_mesh<TypeParam, HierarchicalGrid>(
        mesh, 2000, 2000, 210, HierarchicalGridConfig{.top_cells_exponent = 0.0});
    test::expect_agreement_on_mesh<TypeParam, HierarchicalGrid>(
        test::sphere_mesh(4), 2000, 2000, 211,
        HierarchicalGridConfig{.top_cells_exponent = 1.0, .max_resolution = 4});
}

TYPED_TEST(HierarchicalGridTest, RaysAlongCellBoundariesOfEveryLevel) {
    // Rays lying exactly in cell boundary planes (and along cell edges) of the top grid and
    // of sub-grids at every depth, and in the mesh's own planes.
    const test::BuiltMesh<TypeParam, HierarchicalGrid> built(
        test::integer_cube(6),
        HierarchicalGridConfig{.max_primitives_per_cell = 2, .max_depth = 3});
    const HierarchicalGrid<TriangleSet<TypeParam>>& hgrid = built.structure;
    ASSERT_GT(hgrid.grid_count(), 10u);
    test::Random random(212);
    std::vector<Ray> rays;
    for (int n = 0; n < 8000; ++n) {
        const int level = n % 4 == 0 ? 0 : random.integer(0, int(hgrid.grid_count()) - 1);
        test::add_cell_boundary_rays(hgrid.geometry(level), n, 0.5, random, rays);
    }
    const test::AgreementCounts counts = test::expect_agreement(hgrid, built.brute, rays, 4);
    EXPECT_GT(counts.hits, counts.rays / 5);
}

TYPED_TEST(HierarchicalGridTest, FlatBoundsAgree) {
    const test::BuiltMesh<TypeParam, HierarchicalGrid> built(test::flat_soup(2000, 213));
    for (std::size_t k = 0; k < built.structure.grid_count(); ++k)
        EXPECT_EQ(built.structure.geometry(k).resolution[2], 1);
    const test::AgreementCounts counts = test::expect_agreement(
        built.structure, built.brute, test::rays_along_a_plane(6000, 214), 4);
    EXPECT_GT(counts.hits, counts.rays / 10);
}

TYPED_TEST(HierarchicalGridTest, IdenticalTrianglesStayOneListAndTiesGoToTheLowestIndex) {
    // A sub-grid cannot separate 300 copies of one triangle: every sub-cell they cross would
    // list all of them. The cost estimate sees that and keeps the top grid's lists.
    const TestMesh copies = test::identical_triangles(300);
    const test::BuiltMesh<TypeParam, HierarchicalGrid> built(copies);
    EXPECT_EQ(built.structure.grid_count(), 1u);
    EXPECT_EQ(built.structure.depth(), 0);
    EXPECT_EQ(built.structure.stats().references % 300, 0u);
    test::expect_identical_copies_each_once(built.structure, 300);
    test::expect_agreement(built.structure, built.brute,
                           test::incoherent_rays(test::mesh_bounds(copies), 500, 215), 1);
}

TYPED_TEST(HierarchicalGridTest, EmptySetAndSinglePrimitive) {
    const TriangleSet<TypeParam> empty;
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(empty);
    test::expect_empty_set_answers_nothing(hgrid);
    EXPECT_EQ(hgrid.grid_count(), 0u);
    EXPECT_TRUE(hgrid.primitives_at(Point3(0, 0, 0)).empty());
    const test::BuiltMesh<TypeParam, HierarchicalGrid> one(test::single_triangle());
    EXPECT_EQ(one.structure.grid_count(), 1u);
    test::expect_single_triangle_answers(one.structure);
}

TYPED_TEST(HierarchicalGridTest, InvalidRaysGiveNoHitAndNoHang) {
    const test::BuiltMesh<TypeParam, HierarchicalGrid> built(test::sphere_mesh(3));
    test::expect_invalid_rays_answer_nothing(built.structure);
    test::expect_odd_rays_agree(built.structure, built.brute, Point3(-2, 0.1, 0.1),
                                Point3(0, 0, 0));
}

TYPED_TEST(HierarchicalGridTest, ConcurrentQueriesGiveTheSameAnswers) {
    // Camera rays toward the teapot only, where the sub-grids are.
    test::expect_concurrent_answers_on_mesh<TypeParam, HierarchicalGrid>(
        test::teapot_in_stadium(), Aabb(Point3(-1, -1, -1), Point3(1, 1, 1)), 20000, 216);
}

TYPED_TEST(HierarchicalGridTest, NearlyCoincidentTrianglesAcrossACellBoundary) {
    auto build = [](const TestMesh& mesh) { return top_geometry<TypeParam>(mesh); };
    const test::BuiltMesh<TypeParam, HierarchicalGrid> built(
        test::twin_triangles_across_a_cell_boundary<TypeParam>(build), kFineTop);
    test::expect_agreement(built.structure, built.brute, test::rays_through_twins(20000, 218), 16);
}

TEST(HierarchicalGrid, FindsFloatHitsJustOutsideATriangleAndStopsWellPastTheBest) {
    auto build = [](const TestMesh& mesh) { return top_geometry<float>(mesh); };
    test::float_edge_next_to_a_cell_boundary(build, [](const TestMesh& mesh, const Ray& ray) {
        const test::BuiltMesh<float, HierarchicalGrid> built(mesh, kFineTop);
        QueryScratch scratch;
        HitRecord expected, actual;
        ASSERT_TRUE(built.brute.intersect(ray, expected, scratch));
        ASSERT_EQ(expected.primitive, 16u);
        ASSERT_TRUE(built.structure.intersect(ray, actual, scratch));
        EXPECT_EQ(actual.primitive, 16u);
        EXPECT_EQ(actual.t, expected.t);
    });
    const test::BuiltMesh<float, HierarchicalGrid> twins(
        test::twin_triangles_across_a_cell_boundary<float>(build, 0.03), kFineTop);
    test::expect_agreement(twins.structure, twins.brute, test::rays_through_twins(20000, 219, 3e5),
                           16);
}

TEST(HierarchicalGrid, EveryPointOfAPrimitiveFindsItInItsInnermostCell) {
    // The build invariant at every level: a ray through any point of a triangle tests that
    // triangle there. Points on the triangles (random barycentrics, corners, edge midpoints),
    // located cell by cell down the hierarchy.
    // (With box assignment the long thin triangles' boxes fill their cells, so no sub-grid
    // separates them and the soup stays one level; everything else nests.)
    const std::vector<TestMesh> meshes = {test::long_thin_soup(1000, 223),
                                          test::teapot_in_stadium(), test::sphere_mesh(5)};
    for (std::size_t m = 0; m < meshes.size(); ++m) {
        const TriangleSet<double> set(meshes[m].vertices, meshes[m].triangles);
        for (const bool triangle_test : {false, true}) {
            HierarchicalGrid<TriangleSet<double>> hgrid;
            hgrid.build(set, HierarchicalGridConfig{.max_primitives_per_cell = 4,
                                                    .triangle_box_test = triangle_test});
            if (triangle_test || m > 0) {
                EXPECT_GT(hgrid.depth(), 0) << m;
            }
            test::Random random(224);
            std::size_t missing = 0, checked = 0;
            for (std::uint32_t i = 0; i < set.size(); ++i) {
                const Point3 a = set.corner(i, 0), b = set.corner(i, 1), c = set.corner(i, 2);
                std::vector<Point3> points = {a, b, c, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)};
                for (int k = 0; k < 10; ++k) {
                    double u = random.uniform(), v = random.uniform();
                    if (u + v > 1) u = 1 - u, v = 1 - v;
                    points.push_back(a + u * (b - a) + v * (c - a));
                }
                for (const Point3& p : points) {
                    const auto list = hgrid.primitives_at(p);
                    ++checked;
                    missing += std::find(list.begin(), list.end(), i) == list.end();
                }
            }
            EXPECT_EQ(missing, 0u) << "triangle test " << triangle_test << " of " << checked;
        }
    }
}

TEST(HierarchicalGrid, TestsFarFewerPrimitivesThanTheRegularGridInTeapotInStadium) {
    // The regular grid spreads its cells over the stadium, so the teapot (a 2048-triangle
    // sphere mesh 1/200 of the stadium's size) falls into a few cells of hundreds of
    // triangles each. The hierarchy refines exactly those cells. Measured on rays aimed at
    // the teapot: about 1,960 primitive tests per ray for the grid, 7.3 for the hierarchy.
    // Over the whole stadium most rays only meet the big triangles and both test about 1.3
    // to 1.5 per ray; the few that pass the teapot cost the grid hundreds.
    const TestMesh mesh = test::teapot_in_stadium();
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    RegularGrid<TriangleSet<float>> grid;
    grid.build(set);
    HierarchicalGrid<TriangleSet<float>> hgrid;
    hgrid.build(set);
    EXPECT_GT(hgrid.depth(), 0);
    QueryScratch scratch;
    auto tests_per_ray = [&](const Accelerator<TriangleSet<float>>& structure,
                             const std::vector<Ray>& rays) {
        TraversalCounters counters;
        for (const Ray& ray : rays) {
            HitRecord record;
            structure.intersect_counted(ray, record, scratch, counters);
        }
        return double(counters.primitives_tested) / double(rays.size());
    };
    const std::vector<Ray> at_teapot =
        test::camera_rays(Aabb(Point3(-1, -1, -1), Point3(1, 1, 1)), 5000, 225);
    const std::vector<Ray> everywhere = test::incoherent_rays(test::mesh_bounds(mesh), 20000, 226);
    const double grid_at_teapot = tests_per_ray(grid, at_teapot);
    const double hgrid_at_teapot = tests_per_ray(hgrid, at_teapot);
    EXPECT_LT(100.0 * hgrid_at_teapot, grid_at_teapot);
    EXPECT_LT(hgrid_at_teapot, 10.0);
    EXPECT_LT(tests_per_ray(hgrid, everywhere), tests_per_ray(grid, everywhere));
}

TEST(HierarchicalGrid, CountersAreConsistent) {
    const TestMesh sphere = test::sphere_mesh(6);
    const test::BuiltMesh<float, HierarchicalGrid> built(sphere);
    const HierarchicalGrid<TriangleSet<float>>& hgrid = built.structure;
    QueryScratch scratch;
    TraversalCounters intersect_counters, occluded_counters;
    const std::vector<Ray> rays = test::camera_rays(test::mesh_bounds(sphere), 2000, 227);
    for (const Ray& ray : rays) {
        HitRecord record;
        hgrid.intersect_counted(ray, record, scratch, intersect_counters);
        hgrid.occluded_counted(ray, scratch, occluded_counters);
    }
    // Measured 8.5 primitive tests per camera ray (32,768 for brute force), 8.5 cells and 2.9
    // grid boxes (the top grid's and the sub-grids' entered).
    const double per_ray = double(intersect_counters.primitives_tested) / double(rays.size());
    EXPECT_LT(per_ray, 15.0);
    EXPECT_GT(per_ray, 0.5);
    EXPECT_GE(intersect_counters.boxes_tested, rays.size());
    EXPECT_GT(intersect_counters.nodes_visited, intersect_counters.boxes_tested);
    EXPECT_LE(occluded_counters.primitives_tested, intersect_counters.primitives_tested);
}

TEST(HierarchicalGrid, BadConfigurationsThrowAndTheFactoryBuildsIt) {
    const TestMesh cube = test::integer_cube(1);
    const TriangleSet<float> set(cube.vertices, cube.triangles);
    HierarchicalGrid<TriangleSet<float>> hgrid;
    using Config = HierarchicalGridConfig;
    EXPECT_THROW(hgrid.build(set, Config{.top_cells_exponent = -0.1}), InvalidParameter);
    EXPECT_THROW(hgrid.build(set, Config{.top_cells_exponent = 1.5}), InvalidParameter);
    EXPECT_THROW(hgrid.build(set, Config{.max_primitives_per_cell = 0}), InvalidParameter);
    EXPECT_THROW(hgrid.build(set, Config{.sub_cells_per_primitive = 0.0}), InvalidParameter);
    EXPECT_THROW(hgrid.build(set, Config{.max_depth = -1}), InvalidParameter);
    EXPECT_THROW(hgrid.build(set, Config{.max_depth = 9}), InvalidParameter);
    EXPECT_THROW(hgrid.build(set, Config{.max_resolution = 0}), InvalidParameter);
    AcceleratorConfig config;
    config.hierarchical_grid.max_depth = 1;
    test::expect_factory_builds("hgrid", set, config);
}

}  // namespace
}  // namespace csgrt
