// Welding a soup back into a solid, and smooth shading against the interpolated normal.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

/// The shading normal a hit must have: the corner normals `normal_at(k)` of the hit triangle
/// interpolated by the hit point's barycentrics (long double, from the stored corners).
template <class NormalAt>
Eigen::Matrix<long double, 3, 1> interpolated(const Mesh& mesh, const Hit& hit,
                                              NormalAt&& normal_at) {
    using LongVector = Eigen::Matrix<long double, 3, 1>;
    const LongVector a = mesh.corner(hit.primitive_id, 0).cast<long double>();
    const LongVector b = mesh.corner(hit.primitive_id, 1).cast<long double>();
    const LongVector c = mesh.corner(hit.primitive_id, 2).cast<long double>();
    const LongVector p = hit.point.cast<long double>();
    const LongVector n = (b - a).cross(c - a);
    const long double u = (p - a).cross(c - a).dot(n) / n.squaredNorm();
    const long double v = (b - a).cross(p - a).dot(n) / n.squaredNorm();
    const LongVector n0 = normal_at(0).template cast<long double>();
    const LongVector n1 = normal_at(1).template cast<long double>();
    const LongVector n2 = normal_at(2).template cast<long double>();
    return ((1.0L - u - v) * n0 + u * n1 + v * n2).normalized();
}

std::filesystem::path temporary_file(const std::string& stem, const std::string& extension) {
    return std::filesystem::temp_directory_path() /
           ("csgrt_" + stem + "_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + extension);
}

TEST(FileNormals, ObjCornerNormalsAreInterpolatedAndFollowAFlippedTriangle) {
    // A coarse sphere written as OBJ with its own normal at every corner of every face: the
    // vertex's direction tilted by a random vector per corner, so that one vertex has a
    // different normal in each face (a per-vertex reading would keep only one of them). Face 5
    // is written the wrong way round; validation turns it over, and its corner normals must
    // turn with its corners.
    const test::TestMesh sphere = test::sphere_mesh(1);
    test::Random random(16);
    std::vector<std::array<Eigen::Vector3f, 3>> written(sphere.triangles.size());
    std::vector<std::array<std::uint32_t, 3>> faces = sphere.triangles;
    std::swap(faces[5][1], faces[5][2]);
    const std::filesystem::path path = temporary_file("normals", ".obj");
    {
        std::ofstream out(path);
        out.precision(9);
        for (const Eigen::Vector3d& p : sphere.vertices)
            out << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
        for (std::size_t f = 0; f < faces.size(); ++f) {
            for (int k = 0; k < 3; ++k) {
                const Eigen::Vector3d n =
                    (sphere.vertices[faces[f][k]] + 0.4 * random.unit_vector()).normalized();
                // As the loader keeps it: the float, normalised.
                written[f][k] = n.cast<float>().normalized();
                out << "vn " << n.x() << " " << n.y() << " " << n.z() << "\n";
            }
        }
        for (std::size_t f = 0; f < faces.size(); ++f) {
            out << "f";
            for (int k = 0; k < 3; ++k) out << " " << faces[f][k] + 1 << "//" << 3 * f + k + 1;
            out << "\n";
        }
    }
    const std::shared_ptr<Mesh> mesh = Mesh::load(path);
    MeshConfig computed_config;
    computed_config.file_normals = false;
    const std::shared_ptr<Mesh> computed = Mesh::load(path, computed_config);
    std::filesystem::remove(path);
    EXPECT_TRUE(mesh->report().file_normals);
    EXPECT_EQ(mesh->report().flipped_triangles, 1u);
    EXPECT_NE(describe(mesh->report()).find("normals from the file"), std::string::npos);
    int checked = 0, differ_from_computed = 0, flipped_face = 0;
    long double max_error = 0;
    for (int r = 0; r < 600; ++r) {
        const Point3 origin = 3.0 * random.unit_vector();
        const Ray ray{origin, 0.3 * random.unit_vector() - origin};
        const std::optional<Hit> hit = mesh->intersect(ray);
        if (!hit) continue;
        const std::size_t f = hit->primitive_id;  // no triangle dropped: faces keep their order
        const auto& triangle = mesh->triangle(f);
        // The written normal of the face's corner at the same vertex, wherever validation put
        // that corner.
        static const Eigen::Vector3f kZero = Eigen::Vector3f::Zero();
        auto normal_at = [&](int k) -> const Eigen::Vector3f& {
            for (int j = 0; j < 3; ++j) {
                if (faces[f][j] == triangle[k]) return written[f][j];
            }
            ADD_FAILURE() << "vertex " << triangle[k] << " is not a corner of face " << f;
            return kZero;
        };
        const auto expected = interpolated(*mesh, *hit, normal_at);
        // Float normals and barycentrics: a few 1e-7 (as for computed normals above).
        const long double error = (hit->shading_normal.cast<long double>() - expected).norm();
        EXPECT_NEAR(error, 0.0L, 1e-5L) << "triangle " << f;
        max_error = std::max(max_error, error);
        const std::optional<Hit> other = computed->intersect(ray);
        if (other && (other->shading_normal - hit->shading_normal).norm() > 1e-2)
            ++differ_from_computed;
        flipped_face += f == 5;
        ++checked;
    }
    std::printf(
        "[normals] OBJ by corner: %d hits (%d on the re-oriented face), max |shading - "
        "interpolated| %.2Lg, %d shaded otherwise by computed normals\n",
        checked, flipped_face, max_error, differ_from_computed);
    EXPECT_GT(checked, 400);
    EXPECT_GT(differ_from_computed, checked / 2);
    EXPECT_GT(flipped_face, 0);
}

/// Shading normals of `mesh` on `rays` random rays at it, against the per-vertex `normals`
/// interpolated by the hit's barycentrics (to 1e-5: float normals and barycentrics); with
/// `computed`, how many hits it shades differently (by > 1e-2), so the check can tell.
struct NormalCheck {
    int checked = 0;
    int differ_from_computed = 0;
    long double max_error = 0;
};

NormalCheck check_vertex_normals(const Mesh& mesh, const std::vector<Eigen::Vector3f>& normals,
                                 const Mesh* computed, test::Random& random, int rays,
                                 const std::string& label) {
    NormalCheck check;
    for (int r = 0; r < rays; ++r) {
        const Point3 origin = 3.0 * random.unit_vector();
        const Ray ray{origin, 0.3 * random.unit_vector() - origin};
        const std::optional<Hit> hit = mesh.intersect(ray);
        if (!hit) continue;
        const auto& triangle = mesh.triangle(hit->primitive_id);
        const auto expected = interpolated(
            mesh, *hit, [&](int k) -> const Eigen::Vector3f& { return normals[triangle[k]]; });
        const long double error = (hit->shading_normal.cast<long double>() - expected).norm();
        EXPECT_NEAR(error, 0.0L, 1e-5L) << label;
        check.max_error = std::max(check.max_error, error);
        if (computed) {
            const std::optional<Hit> other = computed->intersect(ray);
            if (other && (other->shading_normal - hit->shading_normal).norm() > 1e-2)
                ++check.differ_from_computed;
        }
        ++check.checked;
    }
    std::printf("[normals] %s: %d hits, max |shading - interpolated| %.2Lg", label.c_str(),
                check.checked, check.max_error);
    if (computed)
        std::printf(", %d shaded otherwise by computed normals", check.differ_from_computed);
    std::printf("\n");
    return check;
}

TEST(FileNormals, PlyVertexNormalsAreInterpolatedAndPartialObjNormalsAreNotUsed) {
    const test::TestMesh sphere = test::sphere_mesh(1);
    test::Random random(23);
    std::vector<Eigen::Vector3f> vertex_normals;
    const std::filesystem::path ply = temporary_file("normals", ".ply");
    {
        std::ofstream out(ply);
        out.precision(9);
        out << "ply\nformat ascii 1.0\nelement vertex " << sphere.vertices.size()
            << "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\n"
               "property float ny\nproperty float nz\nelement face "
            << sphere.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
        for (const Eigen::Vector3d& p : sphere.vertices) {
            // Not unit length: the loader normalises them.
            const Eigen::Vector3d n = 2.5 * (p + 0.5 * random.unit_vector()).normalized();
            vertex_normals.push_back(n.cast<float>().normalized());
            out << p.x() << " " << p.y() << " " << p.z() << " " << n.x() << " " << n.y() << " "
                << n.z() << "\n";
        }
        for (const auto& t : sphere.triangles)
            out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    }
    const std::shared_ptr<Mesh> mesh = Mesh::load(ply);
    std::filesystem::remove(ply);
    EXPECT_TRUE(mesh->report().file_normals);
    EXPECT_GT(check_vertex_normals(*mesh, vertex_normals, nullptr, random, 300, "PLY").checked,
              200);

    // An OBJ whose faces name normals for some corners only: the file's normals are not used
    // (the report says so) and shading is the computed vertex normals'.
    const std::filesystem::path obj = temporary_file("partial_normals", ".obj");
    {
        std::ofstream out(obj);
        for (const Eigen::Vector3d& p : sphere.vertices)
            out << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
        out << "vn 1 0 0\n";
        for (std::size_t f = 0; f < sphere.triangles.size(); ++f) {
            const auto& t = sphere.triangles[f];
            out << "f " << t[0] + 1 << (f == 0 ? "//1 " : " ") << t[1] + 1 << " " << t[2] + 1
                << "\n";
        }
    }
    const std::shared_ptr<Mesh> partial = Mesh::load(obj);
    std::filesystem::remove(obj);
    EXPECT_FALSE(partial->report().file_normals);
    const Mesh plain(TriangleMeshData{sphere.vertices, sphere.triangles, {}, {}});
    for (int r = 0; r < 100; ++r) {
        const Point3 origin = 3.0 * random.unit_vector();
        const Ray ray{origin, 0.3 * random.unit_vector() - origin};
        const std::optional<Hit> a = partial->intersect(ray);
        const std::optional<Hit> b = plain.intersect(ray);
        ASSERT_EQ(a.has_value(), b.has_value());
        // The file's float coordinates against the doubles: normals agree to float rounding.
        if (a) {
            EXPECT_NEAR((a->shading_normal - b->shading_normal).norm(), 0.0, 1e-5);
        }
    }
}

TEST(FileNormals, NoffVertexNormalsAreUsedAsPlyOnes) {
    // OFF with a normal after each vertex's coordinates ("NOFF"; "CNOFF" puts a colour after
    // it): the same per-vertex normals as the PLY test above, interpolated by the barycentrics.
    // The same file as plain OFF (the normals dropped) shades with computed normals, which
    // differ from the file's on most hits, so the check can tell them apart.
    const test::TestMesh sphere = test::sphere_mesh(1);
    for (const bool coloured : {false, true}) {
        test::Random random(29);
        std::vector<Eigen::Vector3f> vertex_normals;
        const std::filesystem::path noff = temporary_file("normals", ".off");
        const std::filesystem::path off = temporary_file("no_normals", ".off");
        {
            std::ofstream with(noff), without(off);
            with.precision(9);
            without.precision(9);
            with << (coloured ? "CNOFF\n" : "NOFF\n");
            without << "OFF\n";
            for (std::ofstream* out : {&with, &without})
                *out << sphere.vertices.size() << " " << sphere.triangles.size() << " 0\n";
            for (const Eigen::Vector3d& p : sphere.vertices) {
                // Not unit length: the loader normalises them.
                const Eigen::Vector3d n = 0.25 * (p + 0.5 * random.unit_vector()).normalized();
                vertex_normals.push_back(n.cast<float>().normalized());
                with << p.x() << " " << p.y() << " " << p.z() << " " << n.x() << " " << n.y() << " "
                     << n.z() << (coloured ? " 0.5 0.25 1.0" : "") << "\n";
                without << p.x() << " " << p.y() << " " << p.z() << "\n";
            }
            for (const auto& t : sphere.triangles) {
                with << "3 " << t[0] << " " << t[1] << " " << t[2] << (coloured ? " 255 0 0" : "")
                     << "\n";
                without << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
            }
        }
        const std::shared_ptr<Mesh> mesh = Mesh::load(noff);
        const std::shared_ptr<Mesh> plain = Mesh::load(off);
        std::filesystem::remove(noff);
        std::filesystem::remove(off);
        EXPECT_TRUE(mesh->report().file_normals) << coloured;
        EXPECT_TRUE(mesh->report().is_closed) << coloured;
        EXPECT_FALSE(plain->report().file_normals);
        const NormalCheck check = check_vertex_normals(*mesh, vertex_normals, plain.get(), random,
                                                       300, coloured ? "CNOFF" : "NOFF");
        EXPECT_GT(check.checked, 200);
        EXPECT_GT(check.differ_from_computed, check.checked / 2);
    }
}

}  // namespace
}  // namespace csgrt
