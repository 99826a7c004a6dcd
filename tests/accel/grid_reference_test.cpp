// The regular and the hierarchical grid on real meshes, against CGAL's exact predicates and,
// on a sample of the rays, bit for bit against brute force.

#include <gtest/gtest.h>

#include <string>

#include "accel/grid_test_common.h"
#include "csgrt/accel/cgal_reference.h"
#include "csgrt/accel/hierarchical_grid.h"
#include "csgrt/accel/mesh_io.h"
#include "csgrt/accel/regular_grid.h"
#include "support/real_meshes.h"
#include "support/reference_check.h"

namespace csgrt {
namespace {

/// Camera-like and incoherent rays per mesh and precision: 3 meshes x 2 precisions x 18,000
/// = 108,000 rays, each judged against CGAL.
constexpr int kRaysPerKind = 9000;
/// Every this-many-th ray is also compared bit for bit with brute force (a brute-force query
/// on the armadillo tests 52,000 triangles, so all of them would take minutes).
constexpr int kBruteForceEvery = 120;

/// Both grids over `mesh` in precision Real against CGAL on camera-like and incoherent rays,
/// and against brute force on a sample of them.
template <class Real>
void expect_reference_agreement(const TriangleMeshData& mesh, const std::string& name) {
    using Set = TriangleSet<Real>;
    const std::string precision = sizeof(Real) == 4 ? "float" : "double";
    const Set set(mesh.vertices, mesh.triangles);
    RegularGrid<Set> grid;
    grid.build(set);
    HierarchicalGrid<Set> hgrid;
    hgrid.build(set);
    BruteForce<Set> brute;
    brute.build(set);
    const CgalReference reference(set);
    Aabb box;
    for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
    std::vector<Ray> rays = test::camera_rays(box, kRaysPerKind, 301);
    const std::vector<Ray> incoherent = test::incoherent_rays(box, kRaysPerKind, 302);
    rays.insert(rays.end(), incoherent.begin(), incoherent.end());
    // The reference answers rays and segments, not whole lines: a t_min of -infinity
    // becomes one far enough back to put the whole mesh's box inside the interval.
    const double reach = (box.upper - box.lower).norm();
    for (Ray& ray : rays) {
        if (ray.t_min == -kInfinity)
            ray.t_min = -2.0 * ((ray.origin - box.center()).norm() + reach) / ray.direction.norm();
    }

    // The tolerances are reference_check.h's ambiguity band: 64 roundoffs of Real in the
    // ray's footprint, stretched by 1 / |cos| of the incidence angle. Rays inside it are
    // counted and printed, not failed; any disagreement outside it is a bug. The hierarchical
    // grid must return the regular grid's answer bit for bit (both return brute force's), so
    // CGAL's verdict on one is its verdict on the other.
    test::ReferenceTally tally;
    QueryScratch scratch;
    std::vector<Ray> sample;
    int differences = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        test::compare_with_reference(grid, set, reference, rays[i], scratch, tally);
        HitRecord from_grid, from_hgrid;
        const bool grid_hit = grid.intersect(rays[i], from_grid, scratch);
        const bool hgrid_hit = hgrid.intersect(rays[i], from_hgrid, scratch);
        differences +=
            grid_hit != hgrid_hit || (grid_hit && (from_grid.t != from_hgrid.t ||
                                                   from_grid.primitive != from_hgrid.primitive));
        if (i % kBruteForceEvery == 0) sample.push_back(rays[i]);
    }
    const std::string label = name + " " + precision;
    tally.print("grid and hgrid " + label);
    EXPECT_EQ(differences, 0) << label;
    EXPECT_EQ(tally.rays, 2 * kRaysPerKind);
    EXPECT_EQ(tally.clear, 0) << label;
    // Camera rays aim at the mesh's box and half the incoherent ones start inside it: a
    // structure that lost triangles would fall far below this.
    EXPECT_GT(tally.hits, tally.rays / 5) << label;
    // Ambiguous rays pass within a few float ulps of an edge; random rays rarely do.
    EXPECT_LT(tally.ambiguous, tally.rays / 200) << label;

    const test::AgreementCounts counts = test::expect_agreement({&grid, &hgrid}, brute, sample, 10);
    EXPECT_EQ(counts.rays, 150);
    EXPECT_EQ(counts.all_hits_checked, 15);
}

TEST(GridReference, AgreesWithCgalOnRealMeshes) {
    int meshes = 0;
    for (const std::string name : {"armadillo", "ChineseDragon-10kv", "elephant"}) {
        const std::filesystem::path path = test::real_mesh(name);
        if (path.empty()) continue;
        ++meshes;
        const TriangleMeshData mesh = load_mesh(path);
        expect_reference_agreement<float>(mesh, name);
        expect_reference_agreement<double>(mesh, name);
    }
    if (meshes == 0) GTEST_SKIP() << "data/fetch-meshes could not provide the real meshes";
    EXPECT_EQ(meshes, 3);
}

}  // namespace
}  // namespace csgrt
