#include "csgrt/accel/regular_grid.h"

#include <gtest/gtest.h>

#include "accel/grid_test_common.h"
#include "csgrt/core/error.h"
#include "support/precisions.h"

namespace csgrt {
namespace {

using test::TestMesh;

template <class Real>
class RegularGridTest : public ::testing::Test {};
TYPED_TEST_SUITE(RegularGridTest, test::Precisions);

// The agreement on in-code meshes at the default settings is in grid_agreement_test.cpp.
TYPED_TEST(RegularGridTest, AgreesWithBruteForceAtOtherResolutions) {
    // Very coarse (one cell), very fine, and a clamp of 3 cells per axis.
    const TestMesh sphere = test::sphere_mesh(3);
    test::expect_agreement_on_mesh<TypeParam, RegularGrid>(sphere, 2000, 2000, 107,
                                                           GridConfig{.cells_per_primitive = 1e-6});
    test::expect_agreement_on_mesh<TypeParam, RegularGrid>(sphere, 2000, 2000, 108,
                                                           GridConfig{.cells_per_primitive = 64});
    test::expect_agreement_on_mesh<TypeParam, RegularGrid>(sphere, 2000, 2000, 109,
                                                           GridConfig{.max_resolution = 3});
}

TYPED_TEST(RegularGridTest, RaysAlongCellBoundariesAndGridFaces) {
    // Rays lying exactly in the planes between cells and in the grid's faces, and along the
    // lines where two such planes meet: the DDA must not skip the cells on either side.
    for (const double density : {1.0, 8.0}) {
        const test::BuiltMesh<TypeParam, RegularGrid> built(
            test::integer_cube(6), GridConfig{.cells_per_primitive = density});
        test::Random random(110);
        std::vector<Ray> rays;
        for (int n = 0; n < 6000; ++n)
            test::add_cell_boundary_rays(built.structure.geometry(), n, 0.3, random, rays);
        const test::AgreementCounts counts =
            test::expect_agreement(built.structure, built.brute, rays, 4);
        EXPECT_GT(counts.hits, counts.rays / 5);
    }
}

TYPED_TEST(RegularGridTest, FlatBoundsGetOneCellAcrossAndAgree) {
    const test::BuiltMesh<TypeParam, RegularGrid> built(test::flat_soup(500, 11));
    EXPECT_EQ(built.structure.geometry().resolution[2], 1);
    // The cells spread over the plane instead: about cells_per_primitive * N of them.
    EXPECT_GT(built.structure.geometry().cell_count(), 500u);
    const test::AgreementCounts counts =
        test::expect_agreement(built.structure, built.brute, test::rays_along_a_plane(6000, 12), 4);
    EXPECT_GT(counts.hits, counts.rays / 10);
}

TYPED_TEST(RegularGridTest, IdenticalTrianglesShareOneCellAndTiesGoToTheLowestIndex) {
    // 300 copies of one triangle: more than the mailbox has slots, so all_hits must still
    // report each exactly once.
    const TestMesh copies = test::identical_triangles(300);
    const test::BuiltMesh<TypeParam, RegularGrid> built(copies);
    const detail::GridGeometry& g = built.structure.geometry();
    for (int z = 0; z < g.resolution[2]; ++z) {
        for (int y = 0; y < g.resolution[1]; ++y) {
            for (int x = 0; x < g.resolution[0]; ++x) {
                const std::size_t listed = built.structure.cell_primitives(x, y, z).size();
                EXPECT_TRUE(listed == 0 || listed == 300) << listed;
            }
        }
    }
    test::expect_identical_copies_each_once(built.structure, 300);
    test::expect_agreement(built.structure, built.brute,
                           test::incoherent_rays(test::mesh_bounds(copies), 500, 13), 1);
}

TYPED_TEST(RegularGridTest, EmptySetAndSinglePrimitive) {
    test::expect_empty_structure_answers_nothing<TypeParam, RegularGrid>();
    const test::BuiltMesh<TypeParam, RegularGrid> one(test::single_triangle());
    EXPECT_EQ(one.structure.geometry().resolution[2], 1);  // flat in z: one cell across
    test::expect_single_triangle_answers(one.structure);
}

TYPED_TEST(RegularGridTest, InvalidRaysGiveNoHitAndNoHang) {
    const test::BuiltMesh<TypeParam, RegularGrid> built(test::integer_cube(2));
    test::expect_invalid_rays_answer_nothing(built.structure);
    // Denormal and huge direction components, and an origin far away: valid, and answered.
    test::expect_odd_rays_agree(built.structure, built.brute, Point3(-1, 0.5, 0.5),
                                Point3(1, 1, 1));
}

TYPED_TEST(RegularGridTest, ConcurrentQueriesGiveTheSameAnswers) {
    const TestMesh sphere = test::sphere_mesh(5);
    test::expect_concurrent_answers_on_mesh<TypeParam, RegularGrid>(
        sphere, test::mesh_bounds(sphere), 20000, 14);
}

TEST(RegularGrid, FindsFloatHitsJustOutsideATriangleAcrossACellBoundary) {
    // The ray passes outside the triangle's box, in the next cell, but the float test rounds
    // it onto the triangle's edge and reports a hit; the triangle's padding must have put it
    // in that cell too.
    test::float_edge_next_to_a_cell_boundary(
        [](const TestMesh& mesh) {
            const TriangleSet<float> set(mesh.vertices, mesh.triangles);
            RegularGrid<TriangleSet<float>> grid;
            grid.build(set);
            return grid.geometry();
        },
        [](const TestMesh& mesh, const Ray& ray) {
            const TriangleSet<float> set(mesh.vertices, mesh.triangles);
            RegularGrid<TriangleSet<float>> grid;
            grid.build(set);
            BruteForce<TriangleSet<float>> brute;
            brute.build(set);
            QueryScratch scratch;
            HitRecord expected, actual;
            ASSERT_TRUE(brute.intersect(ray, expected, scratch));
            ASSERT_EQ(expected.primitive, 16u);
            EXPECT_FALSE(set.bounds(16).contains(ray.at(expected.t)));
            ASSERT_TRUE(grid.intersect(ray, actual, scratch));
            EXPECT_EQ(actual.primitive, 16u);
            EXPECT_EQ(actual.t, expected.t);
            EXPECT_TRUE(grid.occluded(ray, scratch));
        });
}

TYPED_TEST(RegularGridTest, NearlyCoincidentTrianglesAcrossACellBoundary) {
    auto build = [](const TestMesh& mesh) {
        return test::BuiltMesh<TypeParam, RegularGrid>(mesh).structure.geometry();
    };
    const test::BuiltMesh<TypeParam, RegularGrid> built(
        test::twin_triangles_across_a_cell_boundary<TypeParam>(build));
    const std::vector<Ray> rays = test::rays_through_twins(20000, 24);
    test::expect_agreement(built.structure, built.brute, rays, 16);
    test::expect_both_twins_win(built.brute, rays);
}

TEST(RegularGrid, StopsOnlyWellPastTheBestHitForRaysFromFarAway) {
    // From 3e5 away, float rounds the ray's origin by about 0.015 and t by as much: twins
    // 0.03 apart (more than their cells' padding) tie or swap, and the far one, with the
    // lower index, often wins. The stopping margin grows with the origin's magnitude so the
    // walk goes on into the far twin's cell.
    auto build = [](const TestMesh& mesh) {
        return test::BuiltMesh<float, RegularGrid>(mesh).structure.geometry();
    };
    const test::BuiltMesh<float, RegularGrid> built(
        test::twin_triangles_across_a_cell_boundary<float>(build, 0.03));
    const std::vector<Ray> rays = test::rays_through_twins(20000, 25, 3e5);
    test::expect_agreement(built.structure, built.brute, rays, 16);
    test::expect_both_twins_win(built.brute, rays);
}

TEST(RegularGrid, UnboundedShapesAreTestedByEveryRay) {
    // A shape with infinite bounds cannot go into cells; it is kept aside and tested by every
    // ray, so the answers still equal brute force's.
    auto shapes = test::random_spheres(500, 19);
    shapes.push_back(std::make_shared<test::UnboundedPlane>(2.0));
    const ShapeSet set(shapes);
    RegularGrid<ShapeSet> grid;
    grid.build(set);
    EXPECT_EQ(grid.unbounded_primitives().size(), 1u);
    BruteForce<ShapeSet> brute;
    brute.build(set);
    const Aabb box(Point3(0, 0, 0), Point3(10, 10, 10));
    const test::AgreementCounts counts =
        test::expect_agreement(grid, brute, test::incoherent_rays(box, 4000, 20), 4);
    EXPECT_GT(counts.hits, counts.rays / 2);
}

/// Whether the triangle (a, b, c) and the closed box share a point, by clipping the triangle
/// to the box's six half-spaces (Sutherland & Hodgman 1974): independent of the
/// separating-axis test the grid uses.
bool clipped_triangle_is_empty(std::vector<Point3> polygon, const Aabb& box) {
    for (int axis = 0; axis < 3 && !polygon.empty(); ++axis) {
        for (int side = 0; side < 2 && !polygon.empty(); ++side) {
            auto inside = [&](const Point3& p) {
                return side == 0 ? p[axis] >= box.lower[axis] : p[axis] <= box.upper[axis];
            };
            const double plane = side == 0 ? box.lower[axis] : box.upper[axis];
            std::vector<Point3> clipped;
            for (std::size_t i = 0; i < polygon.size(); ++i) {
                const Point3& p = polygon[i];
                const Point3& q = polygon[(i + 1) % polygon.size()];
                if (inside(p)) clipped.push_back(p);
                if (inside(p) != inside(q)) {
                    const double s = (plane - p[axis]) / (q[axis] - p[axis]);
                    Point3 crossing = p + s * (q - p);
                    crossing[axis] = plane;
                    clipped.push_back(crossing);
                }
            }
            polygon = std::move(clipped);
        }
    }
    return polygon.empty();
}

TEST(RegularGrid, EveryCellAPrimitiveOverlapsListsIt) {
    // The build invariant: with box assignment, every cell the primitive's box overlaps lists
    // it; with the triangle-box test, every cell the triangle itself overlaps does. Checked
    // cell by cell against the exact boxes and an independent clipping of each triangle.
    const TestMesh soup = test::long_thin_soup(300, 21);
    const TriangleSet<double> set(soup.vertices, soup.triangles);
    for (const bool triangle_test : {false, true}) {
        RegularGrid<TriangleSet<double>> grid;
        grid.build(set, GridConfig{.cells_per_primitive = 16, .triangle_box_test = triangle_test});
        const detail::GridGeometry& g = grid.geometry();
        std::size_t required = 0, missing = 0;
        for (int z = 0; z < g.resolution[2]; ++z) {
            for (int y = 0; y < g.resolution[1]; ++y) {
                for (int x = 0; x < g.resolution[0]; ++x) {
                    const auto list = grid.cell_primitives(x, y, z);
                    ASSERT_TRUE(std::is_sorted(list.begin(), list.end()));
                    const Aabb cell = g.cell_box(x, y, z);
                    for (std::uint32_t i = 0; i < set.size(); ++i) {
                        if (!cell.overlaps(set.bounds(i))) continue;
                        if (triangle_test &&
                            clipped_triangle_is_empty(
                                {set.corner(i, 0), set.corner(i, 1), set.corner(i, 2)}, cell))
                            continue;
                        ++required;
                        missing += !std::binary_search(list.begin(), list.end(), i);
                    }
                }
            }
        }
        EXPECT_EQ(missing, 0u) << "triangle test " << triangle_test;
        EXPECT_GT(required, set.size());
        EXPECT_GE(grid.stats().references, required);
    }
}

TEST(RegularGrid, EmptyRadiiAreChebyshevDistancesToOccupiedCells) {
    // The walk jumps over the cells within radius - 1 of an empty cell, so a radius too large
    // would skip primitives. Checked against the distance to every occupied cell.
    const TestMesh sphere = test::sphere_mesh(2);
    const TriangleSet<double> set(sphere.vertices, sphere.triangles);
    RegularGrid<TriangleSet<double>> grid;
    grid.build(set, GridConfig{.cells_per_primitive = 64});
    const detail::GridGeometry& g = grid.geometry();
    std::vector<std::array<int, 3>> occupied;
    for (int z = 0; z < g.resolution[2]; ++z)
        for (int y = 0; y < g.resolution[1]; ++y)
            for (int x = 0; x < g.resolution[0]; ++x)
                if (!grid.cell_primitives(x, y, z).empty()) occupied.push_back({x, y, z});
    ASSERT_GT(occupied.size(), 100u);
    int largest = 0;
    for (int z = 0; z < g.resolution[2]; ++z) {
        for (int y = 0; y < g.resolution[1]; ++y) {
            for (int x = 0; x < g.resolution[0]; ++x) {
                int distance = 16;
                for (const auto& [ox, oy, oz] : occupied)
                    distance = std::min(
                        distance, std::max({std::abs(x - ox), std::abs(y - oy), std::abs(z - oz)}));
                ASSERT_EQ(grid.empty_radius(x, y, z), distance) << x << " " << y << " " << z;
                largest = std::max(largest, distance);
            }
        }
    }
    EXPECT_GE(largest, 4);  // the sphere's inside is empty far enough to jump
}

TEST(RegularGrid, TriangleBoxTestCutsReferencesOfLongThinTriangles) {
    // Long, thin, diagonal triangles overlap a small fraction of the cells of their boxes.
    // Measured: about 13x fewer references on this soup at 8 cells per primitive.
    const TestMesh soup = test::long_thin_soup(2000, 22);
    const TriangleSet<float> set(soup.vertices, soup.triangles);
    RegularGrid<TriangleSet<float>> boxes, triangles;
    boxes.build(set, GridConfig{.triangle_box_test = false});
    triangles.build(set, GridConfig{.triangle_box_test = true});
    EXPECT_LT(6 * triangles.stats().references, boxes.stats().references)
        << boxes.stats().details << " / " << triangles.stats().details;
}

TEST(RegularGrid, CountersShowFarFewerPrimitiveTestsThanBruteForce) {
    // A camera ray toward a 32,768-triangle sphere mesh visits about 9 cells (jumping over
    // most empty ones) and stops in the first cell that holds its hit: measured 10.0
    // primitive tests per ray (6.3 for occlusion, which stops at any hit) against 32,768 for
    // brute force.
    const TestMesh sphere = test::sphere_mesh(6);
    const TriangleSet<float> set(sphere.vertices, sphere.triangles);
    RegularGrid<TriangleSet<float>> grid;
    grid.build(set);
    const Aabb box = test::mesh_bounds(sphere);
    QueryScratch scratch;
    TraversalCounters intersect_counters, occluded_counters;
    int hits = 0;
    const std::vector<Ray> rays = test::camera_rays(box, 2000, 23);
    for (const Ray& ray : rays) {
        HitRecord record;
        hits += grid.intersect_counted(ray, record, scratch, intersect_counters);
        grid.occluded_counted(ray, scratch, occluded_counters);
    }
    const double per_ray = double(intersect_counters.primitives_tested) / double(rays.size());
    EXPECT_LT(per_ray, 20.0);
    EXPECT_GT(per_ray, 0.5);
    EXPECT_GT(intersect_counters.nodes_visited, rays.size());
    EXPECT_EQ(intersect_counters.boxes_tested, rays.size());
    // Occlusion stops at the first hit, so it never tests more.
    EXPECT_LE(occluded_counters.primitives_tested, intersect_counters.primitives_tested);
    EXPECT_GT(hits, 300);
}

TEST(RegularGrid, ResolutionFollowsTheDensityHeuristic) {
    // A cube of side 10 with 1000 primitives at 8 cells per primitive: a = cbrt(1000 / 8000)
    // = 0.5, so 20 cells per axis.
    const Aabb cube(Point3(0, 0, 0), Point3(10, 10, 10));
    detail::GridGeometry g = detail::choose_grid_geometry(cube, 1000, 8.0, 256);
    EXPECT_EQ(g.resolution, (std::array<int, 3>{20, 20, 20}));
    EXPECT_DOUBLE_EQ(g.cell_size.x(), 0.5);
    // Clamped per axis.
    g = detail::choose_grid_geometry(cube, 1000, 8.0, 7);
    EXPECT_EQ(g.resolution, (std::array<int, 3>{7, 7, 7}));
    // Flat: one cell across, the rest spread over the plane (a = sqrt(100 / 8000)).
    g = detail::choose_grid_geometry(Aabb(Point3(0, 0, 3), Point3(10, 10, 3)), 1000, 8.0, 256);
    EXPECT_EQ(g.resolution, (std::array<int, 3>{89, 89, 1}));
    EXPECT_EQ(g.inverse_cell_size.z(), 0.0);
    // Nearly flat: the thin axis rounds to one cell and the plane gets the cells instead.
    g = detail::choose_grid_geometry(Aabb(Point3(0, 0, 0), Point3(10, 10, 1e-3)), 1000, 8.0, 256);
    EXPECT_EQ(g.resolution, (std::array<int, 3>{89, 89, 1}));
    // A line and a point.
    g = detail::choose_grid_geometry(Aabb(Point3(0, 0, 0), Point3(0, 5, 0)), 10, 8.0, 256);
    EXPECT_EQ(g.resolution, (std::array<int, 3>{1, 80, 1}));
    g = detail::choose_grid_geometry(Aabb(Point3(1, 1, 1), Point3(1, 1, 1)), 10, 8.0, 256);
    EXPECT_EQ(g.cell_count(), 1u);
    // Cell coordinates clamp outside points and NaN into the grid.
    g = detail::choose_grid_geometry(cube, 1000, 8.0, 256);
    EXPECT_EQ(g.cell_coordinate(-3.0, 0), 0);
    EXPECT_EQ(g.cell_coordinate(10.0, 0), 19);
    EXPECT_EQ(g.cell_coordinate(1e300, 0), 19);
    EXPECT_EQ(g.cell_coordinate(std::numeric_limits<double>::quiet_NaN(), 0), 0);
    EXPECT_EQ(g.cell_coordinate(0.5, 0), 1);
}

TEST(RegularGrid, BadConfigurationsThrowAndTheFactoryBuildsIt) {
    const TestMesh cube = test::integer_cube(1);
    const TriangleSet<float> set(cube.vertices, cube.triangles);
    RegularGrid<TriangleSet<float>> grid;
    EXPECT_THROW(grid.build(set, GridConfig{.cells_per_primitive = 0.0}), InvalidParameter);
    EXPECT_THROW(grid.build(set, GridConfig{.cells_per_primitive = -1.0}), InvalidParameter);
    EXPECT_THROW(grid.build(set, GridConfig{.cells_per_primitive = kInfinity}), InvalidParameter);
    EXPECT_THROW(grid.build(set, GridConfig{.max_resolution = 0}), InvalidParameter);
    AcceleratorConfig config;
    config.grid.cells_per_primitive = 2.0;
    test::expect_factory_builds("grid", set, config);
}

}  // namespace
}  // namespace csgrt
