#include "csgrt/mesh/mesh_tools.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "csgrt/core/error.h"
#include "support/meshes.h"
#include "support/real_meshes.h"
#include "support/test_scale.h"

namespace csgrt {
namespace {

TriangleMeshData to_data(const test::TestMesh& mesh) {
    return TriangleMeshData{mesh.vertices, mesh.triangles, {}};
}

TEST(LoopSubdivide, OctahedronGetsLoopsWeights) {
    // One level on the regular octahedron, worked by hand with Loop's rules: an old vertex of
    // valence 4 keeps 1 - 4 beta of itself, beta = (5/8 - (3/8 + cos(2 pi / 4) / 4)^2) / 4 =
    // 31/256, and its four neighbours sum to zero, so it lands at radius 132/256; a new edge
    // vertex is 3/8 of the edge's ends plus 1/8 of the two opposite corners, which cancel.
    MeshReport report;
    const TriangleMeshData finer = loop_subdivide(to_data(test::sphere_mesh(0)), 1, &report);
    EXPECT_EQ(finer.triangles.size(), 32u);
    EXPECT_EQ(finer.vertices.size(), 6u + 12u);  // V + E
    EXPECT_TRUE(report.is_closed);
    int old_vertices = 0, edge_vertices = 0;
    for (const Eigen::Vector3d& v : finer.vertices) {
        const Eigen::Vector3d a = v.cwiseAbs();
        if (std::abs(v.norm() - 132.0 / 256.0) < 1e-15 && a.maxCoeff() == v.norm()) ++old_vertices;
        if ((a - Eigen::Vector3d(0.375, 0.375, 0)).cwiseAbs().maxCoeff() < 1e-15 ||
            (a - Eigen::Vector3d(0.375, 0, 0.375)).cwiseAbs().maxCoeff() < 1e-15 ||
            (a - Eigen::Vector3d(0, 0.375, 0.375)).cwiseAbs().maxCoeff() < 1e-15) {
            ++edge_vertices;
        }
    }
    EXPECT_EQ(old_vertices, 6);
    EXPECT_EQ(edge_vertices, 12);
}

TEST(LoopSubdivide, MultipliesTrianglesByFourAndStaysClosedInsideTheHull) {
    const TriangleMeshData sphere = to_data(test::sphere_mesh(2));
    for (int levels : {1, 2, 3}) {
        MeshReport report;
        const TriangleMeshData finer = loop_subdivide(sphere, levels, &report);
        EXPECT_EQ(finer.triangles.size(), sphere.triangles.size() << (2 * levels));
        EXPECT_TRUE(report.is_closed);
        EXPECT_EQ(report.components, 1u);
        EXPECT_EQ(report.flipped_triangles, 0u);  // the winding survives
        // Closed genus 0: V - E + F = 2 with E = 3F/2.
        EXPECT_EQ(finer.vertices.size(), 2 + finer.triangles.size() / 2);
        // Loop's points are convex combinations of the control points: inside the unit ball,
        // and near the sphere for a mesh that already approximates it.
        for (const Eigen::Vector3d& v : finer.vertices) {
            EXPECT_LE(v.norm(), 1.0 + 1e-15);
            EXPECT_GT(v.norm(), 0.85);
        }
        EXPECT_EQ(finer.normals.size(), finer.vertices.size());
    }
}

TEST(LoopSubdivide, ArmadilloOnceGives208kTriangles) {
    const std::filesystem::path path = test::real_mesh("armadillo");
    if (path.empty()) GTEST_SKIP() << "data/fetch-meshes could not provide the armadillo";
    const TriangleMeshData armadillo = load_mesh(path);
    MeshReport report;
    const TriangleMeshData finer = loop_subdivide(armadillo, 1, &report);
    EXPECT_EQ(finer.triangles.size(), 208000u);
    EXPECT_EQ(finer.vertices.size(), 26002u + 78000u);
    EXPECT_TRUE(report.is_closed);
}

TEST(LoopSubdivide, RejectsBadLevelsAndNonManifoldMeshes) {
    const TriangleMeshData cube = to_data(test::integer_cube(1));
    EXPECT_THROW(loop_subdivide(cube, -1), InvalidParameter);
    EXPECT_THROW(loop_subdivide(cube, 9), InvalidParameter);
    const TriangleMeshData big = to_data(test::sphere_mesh(6));  // 32768 triangles
    EXPECT_THROW(loop_subdivide(big, 8), InvalidParameter);      // 2^31 triangles
    const TriangleMeshData fin{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                               {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}},
                               {}};
    EXPECT_THROW(loop_subdivide(fin, 1), InvalidParameter);
    // Zero levels: the same mesh, validated.
    EXPECT_EQ(loop_subdivide(cube, 0).triangles.size(), 12u);
}

TEST(Decimate, SphereReachesTheTargetKeepingOriginalVertices) {
    const TriangleMeshData sphere = to_data(test::sphere_mesh(4));  // 2048 triangles
    for (std::size_t target : {1000u, 500u, 100u}) {
        MeshReport report;
        const TriangleMeshData coarse = decimate(sphere, target, &report);
        EXPECT_GE(coarse.triangles.size(), target);
        EXPECT_LE(double(coarse.triangles.size()), 1.03 * double(target)) << target;
        EXPECT_TRUE(report.is_closed);
        EXPECT_EQ(report.components, 1u);
        EXPECT_GT(report.volume, 0.0);
        // Half-edge collapses keep one end of each edge: every vertex is an original one, on
        // the unit sphere.
        for (const Eigen::Vector3d& v : coarse.vertices) EXPECT_NEAR(v.norm(), 1.0, 1e-15);
    }
}

TEST(Decimate, ClosedRealMeshTo1000Triangles) {
    // The armadillo (52,000 triangles); under the sanitizers (label "heavy", reduced scale)
    // the elephant (5,558), which takes the same code through a tenth of the collapses.
    const char* name = test::reduced_scale() ? "elephant" : "armadillo";
    const std::filesystem::path path = test::real_mesh(name);
    if (path.empty()) GTEST_SKIP() << "data/fetch-meshes could not provide the " << name;
    MeshReport original;
    const TriangleMeshData mesh = load_mesh(path, &original);
    ASSERT_TRUE(original.is_closed) << name;
    MeshReport report;
    const TriangleMeshData coarse = decimate(mesh, 1000, &report);
    EXPECT_GE(coarse.triangles.size(), 1000u);
    EXPECT_LE(coarse.triangles.size(), 1030u);
    EXPECT_TRUE(report.is_closed);
    // The quadric metric keeps the shape: the volume stays within a few percent.
    EXPECT_NEAR(report.volume / original.volume, 1.0, 0.1);
}

TEST(Decimate, RejectsBadTargetsAndLeavesSmallMeshesAlone) {
    const TriangleMeshData cube = to_data(test::integer_cube(2));
    EXPECT_THROW(decimate(cube, 3), InvalidParameter);
    const TriangleMeshData same = decimate(cube, 1000);
    EXPECT_EQ(same.triangles.size(), cube.triangles.size());
    EXPECT_EQ(same.vertices, cube.vertices);
}

}  // namespace
}  // namespace csgrt
