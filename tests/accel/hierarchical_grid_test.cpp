#include "csgrt/accel/hierarchical_grid.h"

#include <gtest/gtest.h>

#include "accel/grid_test_common.h"
#include "csgrt/accel/factory.h"
#include "csgrt/core/error.h"

namespace csgrt {
namespace {

using test::TestMesh;

/// A top grid of about one cell per primitive, so the few-triangle scenes of the rounding
/// cases get cell boundaries next to their triangles.
const HierarchicalGridConfig kFineTop{.top_cells_exponent = 1.0};

/// The top grid the hierarchy builds over `mesh` with kFineTop.
template <class Real>
detail::GridGeometry top_geometry(const TestMesh& mesh) {
    const TriangleSet<Real> set(mesh.vertices, mesh.triangles);
    HierarchicalGrid<TriangleSet<Real>> hgrid;
    hgrid.build(set, kFineTop);
    return hgrid.geometry(0);
}

template <class Real>
class HierarchicalGridTest : public ::testing::Test {
protected:
    /// Builds the hierarchy and brute force over `mesh` and checks them against each other on
    /// camera-like, incoherent and axis-parallel rays; returns how many rays were checked.
    int expect_agreement_on(const TestMesh& mesh, int camera, int incoherent, std::uint64_t seed,
                            const HierarchicalGridConfig& config = {}) {
        const TriangleSet<Real> set(mesh.vertices, mesh.triangles);
        HierarchicalGrid<TriangleSet<Real>> hgrid;
        hgrid.build(set, config);
        BruteForce<TriangleSet<Real>> brute;
        brute.build(set);
        const Aabb box = test::mesh_bounds(mesh);
        std::vector<Ray> rays = test::camera_rays(box, camera, seed);
        const std::vector<Ray> more = test::incoherent_rays(box, incoherent, seed + 1);
        const std::vector<Ray> axes = test::axis_rays(box, incoherent / 10, seed + 2);
        rays.insert(rays.end(), more.begin(), more.end());
        rays.insert(rays.end(), axes.begin(), axes.end());
        const test::AgreementCounts counts = test::expect_agreement(hgrid, brute, rays);
        EXPECT_GT(counts.hits, counts.rays / 5) << hgrid.stats().details;
        return counts.rays;
    }
};
using Precisions = ::testing::Types<float, double>;
TYPED_TEST_SUITE(HierarchicalGridTest, Precisions);

// The agreement on in-code meshes at the default settings is in grid_agreement_test.cpp.
TYPED_TEST(HierarchicalGridTest, AgreesWithBruteForceUnderOtherSettings) {
    // No nesting (a plain coarse grid), deep nesting with small cells, one cell on top, and
    // sub-grids forced wherever a cell holds more than one primitive.
    const TestMesh mesh = test::teapot_in_stadium();
    this->expect_agreement_on(mesh, 2000, 2000, 208, HierarchicalGridConfig{.max_depth = 0});
    this->expect_agreement_on(
        mesh, 2000, 2000, 209,
        HierarchicalGridConfig{
            .max_primitives_per_cell = 1, .sub_cells_per_primitive = 16, .max_depth = 6});
    this->expect_agreement_on(mesh, 2000, 2000, 210,
                              HierarchicalGridConfig{.top_cells_exponent = 0.0});
    this->expect_agreement_on(
        test::sphere_mesh(4), 2000, 2000, 211,
        HierarchicalGridConfig{.top_cells_exponent = 1.0, .max_resolution = 4});
}

TYPED_TEST(HierarchicalGridTest, RaysAlongCellBoundariesOfEveryLevel) {
    // Rays lying exactly in cell boundary planes (and along cell edges) of the top grid and
    // of sub-grids at every depth, and in the mesh's own planes.
    const TestMesh cube = test::integer_cube(6);
    const TriangleSet<TypeParam> set(cube.vertices, cube.triangles);
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(set, HierarchicalGridConfig{.max_primitives_per_cell = 2, .max_depth = 3});
    ASSERT_GT(hgrid.grid_count(), 10u);
    BruteForce<TriangleSet<TypeParam>> brute;
    brute.build(set);
    test::Random random(212);
    std::vector<Ray> rays;
    for (int n = 0; n < 8000; ++n) {
        const detail::GridGeometry& g =
            hgrid.geometry(n % 4 == 0 ? 0 : random.integer(0, int(hgrid.grid_count()) - 1));
        auto plane = [&](int axis, int i) { return g.bounds.lower[axis] + i * g.cell_size[axis]; };
        const int axis = n % 3, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        Point3 origin = random.in_box(test::enlarged(g.bounds, 0.5));
        Vector3 direction = random.unit_vector();
        origin[axis] = plane(axis, random.integer(0, g.resolution[axis]));
        direction[axis] = 0.0;
        if (n % 2 == 0) {
            origin[a1] = plane(a1, random.integer(0, g.resolution[a1]));
            direction[a1] = 0.0;
            direction[a2] = n % 4 ? 1.0 : -2.0;
        }
        rays.push_back(Ray{origin, direction});
        Point3 on_mesh_plane = origin;
        on_mesh_plane[axis] = random.integer(0, 6);
        rays.push_back(Ray{on_mesh_plane, direction});
    }
    const test::AgreementCounts counts = test::expect_agreement(hgrid, brute, rays, 4);
    EXPECT_GT(counts.hits, counts.rays / 5);
}

TYPED_TEST(HierarchicalGridTest, FlatBoundsAgree) {
    const TestMesh flat = test::flat_soup(2000, 213);
    const TriangleSet<TypeParam> set(flat.vertices, flat.triangles);
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(set);
    for (std::size_t k = 0; k < hgrid.grid_count(); ++k)
        EXPECT_EQ(hgrid.geometry(k).resolution[2], 1);
    BruteForce<TriangleSet<TypeParam>> brute;
    brute.build(set);
    test::Random random(214);
    std::vector<Ray> rays;
    for (int n = 0; n < 6000; ++n) {
        const Point3 origin(random.uniform(-2, 12), random.uniform(-2, 12), 0.0);
        Vector3 direction = random.unit_vector();
        switch (n % 3) {
            case 0:
                direction.z() = 0.0;
                break;
            case 1:
                direction.z() = random.uniform(-1e-6, 1e-6);
                break;
            default:
                rays.push_back(Ray{origin + Vector3(0, 0, 3), direction});
        }
        rays.push_back(Ray{origin, direction});
    }
    const test::AgreementCounts counts = test::expect_agreement(hgrid, brute, rays, 4);
    EXPECT_GT(counts.hits, counts.rays / 10);
}

TYPED_TEST(HierarchicalGridTest, IdenticalTrianglesStayOneListAndTiesGoToTheLowestIndex) {
    // A sub-grid cannot separate 300 copies of one triangle: every sub-cell they cross would
    // list all of them. The cost estimate sees that and keeps the top grid's lists.
    const TestMesh copies = test::identical_triangles(300);
    const TriangleSet<TypeParam> set(copies.vertices, copies.triangles);
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(set);
    EXPECT_EQ(hgrid.grid_count(), 1u);
    EXPECT_EQ(hgrid.depth(), 0);
    EXPECT_EQ(hgrid.stats().references % 300, 0u);
    QueryScratch scratch;
    const Ray ray{Point3(0.2, 0.2, 5), Vector3(0, 0, -1)};
    HitRecord record;
    ASSERT_TRUE(hgrid.intersect(ray, record, scratch));
    EXPECT_EQ(record.primitive, 0u);
    std::vector<HitRecord> hits;
    hgrid.all_hits(ray, hits, scratch);
    ASSERT_EQ(hits.size(), 300u);
    std::vector<bool> seen(300, false);
    for (const HitRecord& hit : hits) seen[hit.primitive] = true;
    EXPECT_EQ(std::count(seen.begin(), seen.end(), true), 300);
    BruteForce<TriangleSet<TypeParam>> brute;
    brute.build(set);
    test::expect_agreement(hgrid, brute, test::incoherent_rays(test::mesh_bounds(copies), 500, 215),
                           1);
}

TYPED_TEST(HierarchicalGridTest, EmptySetAndSinglePrimitive) {
    const TriangleSet<TypeParam> empty;
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(empty);
    QueryScratch scratch;
    HitRecord record;
    const Ray ray{Point3(0, 0, -1), Vector3(0, 0, 1)};
    EXPECT_FALSE(hgrid.intersect(ray, record, scratch));
    EXPECT_FALSE(hgrid.occluded(ray, scratch));
    std::vector<HitRecord> hits;
    hgrid.all_hits(ray, hits, scratch);
    EXPECT_TRUE(hits.empty());
    EXPECT_EQ(hgrid.grid_count(), 0u);
    EXPECT_TRUE(hgrid.primitives_at(Point3(0, 0, 0)).empty());

    const std::vector<Eigen::Vector3d> vertices = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
    const TriangleSet<TypeParam> one(vertices, triangles);
    hgrid.build(one);
    EXPECT_EQ(hgrid.grid_count(), 1u);
    ASSERT_TRUE(hgrid.intersect(Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2)}, record, scratch));
    EXPECT_EQ(record.t, 0.5);
    EXPECT_EQ(record.primitive, 0u);
    EXPECT_TRUE(hgrid.occluded(Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2), 0.5, 0.5}, scratch));
    EXPECT_FALSE(hgrid.occluded(
        Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2), 0.0, std::nextafter(0.5, 0.0)}, scratch));
    EXPECT_FALSE(hgrid.occluded(
        Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2), std::nextafter(0.5, 1.0), kInfinity}, scratch));
    EXPECT_FALSE(hgrid.intersect(Ray{Point3(1.5, 1.5, -1), Vector3(0, 0, 1)}, record, scratch));
}

TYPED_TEST(HierarchicalGridTest, InvalidRaysGiveNoHitAndNoHang) {
    const TestMesh sphere = test::sphere_mesh(3);
    const TriangleSet<TypeParam> set(sphere.vertices, sphere.triangles);
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(set);
    QueryScratch scratch;
    for (const Ray& ray : test::invalid_rays()) {
        HitRecord record;
        TraversalCounters counters;
        EXPECT_FALSE(hgrid.intersect(ray, record, scratch));
        EXPECT_FALSE(hgrid.intersect_counted(ray, record, scratch, counters));
        EXPECT_FALSE(hgrid.occluded(ray, scratch));
        EXPECT_FALSE(hgrid.occluded_counted(ray, scratch, counters));
        std::vector<HitRecord> hits;
        hgrid.all_hits(ray, hits, scratch);
        EXPECT_TRUE(hits.empty());
    }
    BruteForce<TriangleSet<TypeParam>> brute;
    brute.build(set);
    const std::vector<Ray> odd = {Ray{Point3(-2, 0.1, 0.1), Vector3(1, 1e-310, -1e-310)},
                                  Ray{Point3(-2, 0.1, 0.1), Vector3(1e30, 1e-10, 0)},
                                  Ray{Point3(-1e12, 0.1, 0.1), Vector3(1, 0, 0)},
                                  Ray{Point3(0, 0, 0), Vector3(1e-150, 2e-150, 3e-150)}};
    test::expect_agreement(hgrid, brute, odd, 1);
}

TYPED_TEST(HierarchicalGridTest, ConcurrentQueriesGiveTheSameAnswers) {
    const TestMesh mesh = test::teapot_in_stadium();
    const TriangleSet<TypeParam> set(mesh.vertices, mesh.triangles);
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(set);
    const Aabb box = test::mesh_bounds(mesh);
    std::vector<Ray> rays = test::incoherent_rays(box, 20000, 216);
    const std::vector<Ray> camera =
        test::camera_rays(Aabb(Point3(-1, -1, -1), Point3(1, 1, 1)), 20000, 217);
    rays.insert(rays.end(), camera.begin(), camera.end());
    test::expect_same_answers_concurrently(hgrid, rays, 4);
}

TYPED_TEST(HierarchicalGridTest, NearlyCoincidentTrianglesAcrossACellBoundary) {
    auto build = [](const TestMesh& mesh) { return top_geometry<TypeParam>(mesh); };
    const TestMesh mesh = test::twin_triangles_across_a_cell_boundary<TypeParam>(build);
    const TriangleSet<TypeParam> set(mesh.vertices, mesh.triangles);
    HierarchicalGrid<TriangleSet<TypeParam>> hgrid;
    hgrid.build(set, kFineTop);
    BruteForce<TriangleSet<TypeParam>> brute;
    brute.build(set);
    test::expect_agreement(hgrid, brute, test::rays_through_twins(20000, 218), 16);
}

TEST(HierarchicalGrid, FindsFloatHitsJustOutsideATriangleAndStopsWellPastTheBest) {
    auto build = [](const TestMesh& mesh) { return top_geometry<float>(mesh); };
    test::float_edge_next_to_a_cell_boundary(build, [](const TestMesh& mesh, const Ray& ray) {
        const TriangleSet<float> set(mesh.vertices, mesh.triangles);
        HierarchicalGrid<TriangleSet<float>> hgrid;
        hgrid.build(set, kFineTop);
        BruteForce<TriangleSet<float>> brute;
        brute.build(set);
        QueryScratch scratch;
        HitRecord expected, actual;
        ASSERT_TRUE(brute.intersect(ray, expected, scratch));
        ASSERT_EQ(expected.primitive, 16u);
        ASSERT_TRUE(hgrid.intersect(ray, actual, scratch));
        EXPECT_EQ(actual.primitive, 16u);
        EXPECT_EQ(actual.t, expected.t);
    });
    const TestMesh twins = test::twin_triangles_across_a_cell_boundary<float>(build, 0.03);
    const TriangleSet<float> set(twins.vertices, twins.triangles);
    HierarchicalGrid<TriangleSet<float>> hgrid;
    hgrid.build(set, kFineTop);
    BruteForce<TriangleSet<float>> brute;
    brute.build(set);
    test::expect_agreement(hgrid, brute, test::rays_through_twins(20000, 219, 3e5), 16);
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
    const TriangleSet<float> set(sphere.vertices, sphere.triangles);
    HierarchicalGrid<TriangleSet<float>> hgrid;
    hgrid.build(set);
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
    const auto structure = make_accelerator("hgrid", set, config);
    EXPECT_EQ(structure->name(), "hgrid");
    const AcceleratorStats stats = structure->stats();
    EXPECT_EQ(stats.primitives, 12u);
    EXPECT_GT(stats.nodes, 0u);
    EXPECT_GE(stats.references, 12u);
    EXPECT_GT(stats.bytes, 0u);
    EXPECT_FALSE(stats.details.empty());
}

}  // namespace
}  // namespace csgrt
