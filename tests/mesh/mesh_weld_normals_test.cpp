// Welding a soup back into a solid, and smooth shading against the interpolated normal.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>

#include "csgrt/mesh/mesh.h"
#include "csgrt/mesh/mesh_tools.h"
#include "support/meshes.h"
#include "support/random.h"

namespace csgrt {
namespace {

/// `mesh` as a soup: every corner of every triangle its own vertex, as exporters write meshes
/// with per-corner normals.
TriangleMeshData soup_of(const test::TestMesh& mesh) {
    TriangleMeshData soup;
    for (const auto& t : mesh.triangles) {
        const auto first = static_cast<std::uint32_t>(soup.vertices.size());
        for (std::uint32_t corner : t) soup.vertices.push_back(mesh.vertices[corner]);
        soup.triangles.push_back({first, first + 1, first + 2});
    }
    return soup;
}

TEST(WeldVertices, ASoupOfAClosedCubeBecomesTheClosedCubeAgain) {
    const test::TestMesh cube = test::integer_cube(2);  // 26 vertices, 48 triangles
    TriangleMeshData soup = soup_of(cube);
    ASSERT_EQ(soup.vertices.size(), 144u);
    TriangleMeshData unwelded = soup;
    EXPECT_FALSE(validate_mesh(unwelded).is_closed);
    EXPECT_EQ(weld_vertices(soup), 144u - 26u);
    ASSERT_EQ(soup.vertices.size(), cube.vertices.size());
    const MeshReport report = validate_mesh(soup);
    EXPECT_TRUE(report.is_closed);
    EXPECT_EQ(report.boundary_edges, 0u);
    EXPECT_DOUBLE_EQ(report.volume, 8.0);
    // Positions that differ in the last bit are different vertices: nothing merges.
    TriangleMeshData nudged = soup_of(cube);
    for (std::size_t i = 0; i < nudged.vertices.size(); i += 3)
        nudged.vertices[i].x() = std::nextafter(nudged.vertices[i].x(), 10.0);
    const std::size_t merged = weld_vertices(nudged);
    EXPECT_LT(merged, 144u - 26u);
}

TEST(WeldVertices, TheMeshOptionWeldsAPlyWrittenPerCornerIntoASolid) {
    const test::TestMesh cube = test::integer_cube(1);
    const TriangleMeshData soup = soup_of(cube);
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        ("csgrt_weld_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         ".ply");
    {
        std::ofstream out(path);
        out << "ply\nformat ascii 1.0\nelement vertex " << soup.vertices.size()
            << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
            << soup.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
        for (const auto& v : soup.vertices) out << v.x() << " " << v.y() << " " << v.z() << "\n";
        for (const auto& t : soup.triangles)
            out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    }
    const auto open = Mesh::load(path);
    EXPECT_FALSE(open->is_solid());
    MeshConfig config;
    config.weld_vertices = true;
    const auto welded = Mesh::load(path, config);
    std::filesystem::remove(path);
    EXPECT_TRUE(welded->is_solid());
    EXPECT_EQ(welded->report().welded_vertices, 36u - 8u);
    EXPECT_EQ(welded->report().format, "ply");
    EXPECT_NE(describe(welded->report()).find("28 vertices welded"), std::string::npos);
    // A solid answers point membership.
    EXPECT_TRUE(welded->contains(Point3(0.5, 0.25, 0.75)));
    EXPECT_FALSE(welded->contains(Point3(1.5, 0.25, 0.75)));
}

TEST(SmoothShading, TheShadingNormalIsTheBarycentricInterpolationOfTheVertexNormals) {
    // A coarse sphere: its vertex normals differ a lot across a triangle, so interpolation by
    // the wrong weights (or none) is visible. The expected normal interpolates the vertex
    // normals (validate_mesh's, rounded to float as the mesh stores them) by the barycentrics
    // of the hit point, computed here in long double from the point and the stored corners.
    const test::TestMesh sphere = test::sphere_mesh(1);
    TriangleMeshData data{sphere.vertices, sphere.triangles, {}};
    TriangleMeshData validated = data;
    validate_mesh(validated);
    const Mesh mesh(data);
    test::Random random(4);
    int checked = 0, far_from_face = 0;
    for (int r = 0; r < 500; ++r) {
        const Point3 origin = 3.0 * random.unit_vector();
        const Ray ray{origin, 0.3 * random.unit_vector() - origin};
        const std::optional<Hit> hit = mesh.intersect(ray);
        if (!hit) continue;
        const auto& t = mesh.triangle(hit->primitive_id);
        using LongVector = Eigen::Matrix<long double, 3, 1>;
        const LongVector a = mesh.corner(hit->primitive_id, 0).cast<long double>();
        const LongVector b = mesh.corner(hit->primitive_id, 1).cast<long double>();
        const LongVector c = mesh.corner(hit->primitive_id, 2).cast<long double>();
        const LongVector p = hit->point.cast<long double>();
        const LongVector n = (b - a).cross(c - a);
        const long double area = n.squaredNorm();
        const long double u = (p - a).cross(c - a).dot(n) / area;  // weight of b
        const long double v = (b - a).cross(p - a).dot(n) / area;  // weight of c
        LongVector expected =
            (1.0L - u - v) * validated.normals[t[0]].cast<float>().cast<long double>() +
            u * validated.normals[t[1]].cast<float>().cast<long double>() +
            v * validated.normals[t[2]].cast<float>().cast<long double>();
        expected.normalize();
        // The mesh keeps the barycentrics in float (2^-24 relative) and the normals in float:
        // the interpolated unit vector is good to a few 1e-7; 1e-5 leaves room and still sees
        // a wrong weight (vertex normals differ by ~0.5 across these triangles).
        const Vector3 got = hit->shading_normal;
        EXPECT_NEAR((got.cast<long double>() - expected).norm(), 0.0L, 1e-5L)
            << "triangle " << hit->primitive_id << " u " << u << " v " << v;
        // The face normal is far from it: the comparison can tell interpolation from none.
        if ((hit->geometric_normal.cast<long double>() - expected).norm() > 1e-2L) ++far_from_face;
        ++checked;
    }
    EXPECT_GT(checked, 300);
    EXPECT_GT(far_from_face, checked / 2);
}

TEST(SmoothShading, ACreaseAngleKeepsACubesEdgesSharpAndFlatShadingUsesTheFace) {
    // The cube's faces meet at 90 degrees: under a 30 degree crease every corner normal is its
    // own face's, so shading equals the face normal everywhere; with plain vertex normals it
    // leans toward the neighbouring faces away from a face's centre. On the sphere (the faces
    // around any vertex within 50 degrees of each other at level 2) an 80 degree crease
    // changes nothing.
    const test::TestMesh cube = test::integer_cube(2);
    const TriangleMeshData data{cube.vertices, cube.triangles, {}};
    MeshConfig creased;
    creased.crease_angle = kPi / 6.0;
    MeshConfig flat;
    flat.flat_shading = true;
    const Mesh smooth_cube(data), creased_cube(data, creased), flat_cube(data, flat);
    test::Random random(8);
    int hits = 0, leaning = 0;
    for (int r = 0; r < 400; ++r) {
        const Point3 origin = Point3(1, 1, 1) + 5.0 * random.unit_vector();
        const Ray ray{origin, Point3(1, 1, 1) + random.unit_vector() - origin};
        const std::optional<Hit> smooth = smooth_cube.intersect(ray);
        const std::optional<Hit> sharp = creased_cube.intersect(ray);
        const std::optional<Hit> faceted = flat_cube.intersect(ray);
        ASSERT_EQ(smooth.has_value(), sharp.has_value());
        if (!smooth) continue;
        ++hits;
        // Corner normals in float: the creased normal is the face normal to 2^-24 or so.
        EXPECT_NEAR((sharp->shading_normal - sharp->geometric_normal).norm(), 0.0, 1e-6);
        EXPECT_EQ(faceted->shading_normal, faceted->geometric_normal);
        if ((smooth->shading_normal - smooth->geometric_normal).norm() > 1e-2) ++leaning;
    }
    EXPECT_GT(hits, 300);
    EXPECT_GT(leaning, hits / 2);

    const test::TestMesh sphere = test::sphere_mesh(2);
    const TriangleMeshData sphere_data{sphere.vertices, sphere.triangles, {}};
    MeshConfig wide_crease;
    wide_crease.crease_angle = 80.0 * kPi / 180.0;
    const Mesh smooth_sphere(sphere_data), creased_sphere(sphere_data, wide_crease);
    for (int r = 0; r < 200; ++r) {
        const Point3 origin = 3.0 * random.unit_vector();
        const Ray ray{origin, 0.3 * random.unit_vector() - origin};
        const std::optional<Hit> a = smooth_sphere.intersect(ray);
        const std::optional<Hit> b = creased_sphere.intersect(ray);
        ASSERT_EQ(a.has_value(), b.has_value());
        if (!a) continue;
        // Vertex normals and corner normals come from the same sums, in float: 1e-6.
        EXPECT_NEAR((a->shading_normal - b->shading_normal).norm(), 0.0, 1e-6);
    }
}

}  // namespace
}  // namespace csgrt
