#include "csgrt/mesh/mesh_io.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include "csgrt/core/error.h"
#include "csgrt/mesh/mesh_tools.h"
#include "support/meshes.h"
#include "support/real_meshes.h"
#include "support/test_output.h"

namespace csgrt {
namespace {

const std::filesystem::path kFixtures =
    std::filesystem::path(CSGRT_SOURCE_DIR) / "tests/data/meshes";

TriangleMeshData to_data(const test::TestMesh& mesh) {
    return TriangleMeshData{mesh.vertices, mesh.triangles, {}};
}

Eigen::Vector3d face_normal(const TriangleMeshData& mesh, const std::array<std::uint32_t, 3>& t) {
    return (mesh.vertices[t[1]] - mesh.vertices[t[0]])
        .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
}

double triangle_area(const TriangleMeshData& mesh, const std::array<std::uint32_t, 3>& t) {
    return 0.5 * face_normal(mesh, t).norm();
}

// Every valid fixture describes the box [0,2] x [0,3] x [0,4] (make_fixtures.py).
struct BoxFile {
    const char* name;
    const char* format;
    bool binary;
    std::size_t faces;
    std::size_t triangulated;
};

void PrintTo(const BoxFile& file, std::ostream* out) {
    *out << file.name;
}

class BoxFixture : public ::testing::TestWithParam<BoxFile> {};

TEST_P(BoxFixture, LoadsWithTheRightCountsAndGeometry) {
    const BoxFile& file = GetParam();
    MeshReport report;
    const TriangleMeshData mesh = load_mesh(kFixtures / file.name, &report);
    EXPECT_EQ(report.format, file.format);
    EXPECT_EQ(report.binary, file.binary);
    EXPECT_EQ(report.faces, file.faces);
    EXPECT_EQ(report.triangulated_faces, file.triangulated);
    EXPECT_EQ(report.vertices, 8u);
    EXPECT_EQ(report.triangles, 12u);
    ASSERT_EQ(mesh.vertices.size(), 8u);
    ASSERT_EQ(mesh.triangles.size(), 12u);
    EXPECT_EQ(report.edges, 18u);  // a closed mesh: 3 F / 2
    EXPECT_EQ(report.boundary_edges, 0u);
    EXPECT_EQ(report.non_manifold_edges, 0u);
    EXPECT_EQ(report.flipped_triangles, 0u);  // the fixtures wind outward already
    EXPECT_TRUE(report.is_closed);
    // Integer coordinates: the signed volume is exact.
    EXPECT_EQ(report.volume, 24.0);

    // The corners are exactly those of the box.
    std::set<std::array<double, 3>> corners;
    for (const Eigen::Vector3d& v : mesh.vertices) corners.insert({v.x(), v.y(), v.z()});
    std::set<std::array<double, 3>> expected;
    for (double x : {0.0, 2.0})
        for (double y : {0.0, 3.0})
            for (double z : {0.0, 4.0}) expected.insert({x, y, z});
    EXPECT_EQ(corners, expected);

    // Every triangle lies in a face of the box and its normal points out of the box.
    const Eigen::Vector3d center(1.0, 1.5, 2.0);
    double area = 0.0;
    for (const auto& t : mesh.triangles) {
        const Eigen::Vector3d centroid =
            (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.0;
        EXPECT_GT(face_normal(mesh, t).dot(centroid - center), 0.0);
        area += triangle_area(mesh, t);
    }
    EXPECT_DOUBLE_EQ(area, 2.0 * (2 * 3 + 3 * 4 + 2 * 4));

    // Angle weighting makes a box corner's normal the diagonal, however each face is split:
    // the corner's angles in each face sum to 90 degrees.
    ASSERT_EQ(mesh.normals.size(), 8u);
    for (std::size_t v = 0; v < 8; ++v) {
        const Eigen::Vector3d diagonal = (mesh.vertices[v] - center).cwiseSign() / std::sqrt(3.0);
        EXPECT_NEAR((mesh.normals[v] - diagonal).norm(), 0.0, 1e-15)
            << file.name << " vertex " << v;
    }
}

INSTANTIATE_TEST_SUITE_P(EveryFormat, BoxFixture,
                         ::testing::Values(BoxFile{"box.off", "off", false, 11, 1},
                                           BoxFile{"box_quads.obj", "obj", false, 6, 6},
                                           BoxFile{"box_ascii.ply", "ply", false, 6, 6},
                                           BoxFile{"box_binary.ply", "ply", true, 12, 0},
                                           BoxFile{"box_big_endian.ply", "ply", true, 12, 0},
                                           BoxFile{"box_ascii.stl", "stl", false, 12, 0},
                                           BoxFile{"box_binary.stl", "stl", true, 12, 0}),
                         [](const auto& info) {
                             std::string name = info.param.name;
                             std::replace(name.begin(), name.end(), '.', '_');
                             return name;
                         });

TEST(MeshIo, NonConvexPolygonIsEarClippedInsideItself) {
    // The L (area 3) wound counter-clockwise from +z: a fan from its first corner would
    // produce a triangle outside the L and one wound the other way.
    MeshReport report;
    const TriangleMeshData mesh = load_mesh(kFixtures / "l_shape.obj", &report);
    ASSERT_EQ(mesh.triangles.size(), 4u);
    EXPECT_EQ(report.triangulated_faces, 1u);
    double area = 0.0;
    for (const auto& t : mesh.triangles) {
        const Eigen::Vector3d normal = face_normal(mesh, t);
        EXPECT_GT(normal.z(), 0.0);  // winding kept
        EXPECT_EQ(normal.x(), 0.0);
        EXPECT_EQ(normal.y(), 0.0);
        area += triangle_area(mesh, t);
        const Eigen::Vector3d c =
            (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.0;
        const bool in_l = (c.x() > 0 && c.x() < 2 && c.y() > 0 && c.y() < 1) ||
                          (c.x() > 0 && c.x() < 1 && c.y() > 0 && c.y() < 2);
        EXPECT_TRUE(in_l) << c.transpose();
    }
    EXPECT_DOUBLE_EQ(area, 3.0);
    EXPECT_FALSE(report.is_closed);
    EXPECT_EQ(report.boundary_edges, 6u);
}

struct MalformedFile {
    const char* name;
    std::vector<const char*> expected;  // substrings of the message
};

void PrintTo(const MalformedFile& file, std::ostream* out) {
    *out << file.name;
}

class Malformed : public ::testing::TestWithParam<MalformedFile> {};

TEST_P(Malformed, ThrowsMeshErrorNamingTheFileAndTheProblem) {
    const MalformedFile& file = GetParam();
    const std::filesystem::path path = kFixtures / "malformed" / file.name;
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    try {
        load_mesh(path);
        FAIL() << file.name << " loaded";
    } catch (const MeshError& error) {
        const std::string message = error.what();
        EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
        for (const char* part : file.expected) {
            EXPECT_NE(message.find(part), std::string::npos)
                << "'" << part << "' not in: " << message;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(
    Corpus, Malformed,
    ::testing::Values(
        MalformedFile{"truncated.off", {"truncated", "declares 12 faces", "ends after 11"}},
        MalformedFile{"wrong_counts.off", {"truncated", "13 faces"}},
        MalformedFile{"extra_faces.off", {"line 22", "data after the 11 faces"}},
        MalformedFile{"nan.off", {"line 4", "vertex 1", "non-finite", "'nan'"}},
        MalformedFile{"out_of_range.off",
                      {"line 22", "face 11 refers to vertex 8", "has 8 vertices"}},
        MalformedFile{"empty.off", {"empty file"}},
        MalformedFile{"garbage.off", {"line 1", "not an OFF header"}},
        MalformedFile{"degenerate.off", {"no triangle of non-zero area"}},
        MalformedFile{"truncated.obj", {"line 25", "face 6 has 2 corners"}},
        MalformedFile{"nan.obj", {"line 5", "vertex 1", "non-finite"}},
        MalformedFile{"out_of_range.obj", {"line 25", "vertex 9", "has 8 vertices"}},
        MalformedFile{"zero_index.obj", {"line 25", "vertex 0", "start at 1"}},
        MalformedFile{"empty.obj", {"empty file"}}, MalformedFile{"garbage.obj", {"no faces"}},
        MalformedFile{"no_faces.obj", {"no faces"}},
        MalformedFile{"truncated_ascii.ply", {"line 27", "face 5", "too few values"}},
        MalformedFile{"truncated_binary.ply", {"truncated", "face 11", "declares 12"}},
        MalformedFile{"wrong_counts_ascii.ply", {"truncated", "face 6", "declares 7"}},
        MalformedFile{"wrong_counts_binary.ply", {"data after the last element", "counts"}},
        MalformedFile{"nan_ascii.ply", {"line 15", "vertex 1", "non-finite"}},
        MalformedFile{"nan_binary.ply", {"vertex 1", "non-finite coordinate x"}},
        MalformedFile{"out_of_range_binary.ply", {"face 11 refers to vertex 42", "has 8 vertices"}},
        MalformedFile{"empty.ply", {"empty file"}},
        MalformedFile{"garbage.ply", {"line 1", "not a PLY file"}},
        MalformedFile{"truncated_binary.stl", {"12 facets take 684 bytes", "has 654", "truncated"}},
        MalformedFile{"wrong_count_binary.stl", {"13 facets take 734 bytes", "has 684"}},
        MalformedFile{"truncated_ascii.stl", {"line 83", "facet 11"}},
        MalformedFile{"nan_ascii.stl", {"line 13", "facet 1", "non-finite"}},
        MalformedFile{"nan_binary.stl", {"facet 1", "non-finite"}},
        MalformedFile{"empty.stl", {"empty file"}},
        MalformedFile{"garbage.stl", {"not a binary STL", "not an ASCII STL"}},
        MalformedFile{"degenerate.stl", {"no triangle of non-zero area"}},
        MalformedFile{"repeated_corners.stl", {"no face has three distinct corners"}}),
    [](const auto& info) {
        std::string name = info.param.name;
        std::replace(name.begin(), name.end(), '.', '_');
        return name;
    });

TEST(MeshIo, MissingDirectoryAndUnknownFilesAreErrors) {
    const auto expect_error = [](const std::filesystem::path& path, const char* part) {
        try {
            load_mesh(path);
            ADD_FAILURE() << path << " loaded";
        } catch (const MeshError& error) {
            const std::string message = error.what();
            EXPECT_NE(message.find(path.string()), std::string::npos) << message;
            EXPECT_NE(message.find(part), std::string::npos) << message;
        }
    };
    expect_error(kFixtures / "no_such_mesh.off", "no such file");
    expect_error(kFixtures / "malformed", "not a regular file");
    expect_error(kFixtures / "make_fixtures.py", "unsupported extension");
}

/// A scratch folder of this test, removed on destruction.
class ScratchFolder {
public:
    ScratchFolder()
        : path_(std::filesystem::temp_directory_path() /
                ("csgrt_mesh_io_" + std::to_string(::getpid()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
        std::filesystem::create_directories(path_);
    }
    ~ScratchFolder() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

std::string mesh_error(const std::filesystem::path& path) {
    try {
        load_mesh(path);
    } catch (const MeshError& error) {
        return error.what();
    }
    return "no error";
}

TEST(MeshIo, FifosDevicesAndNulBytesAreRefusedBeforeOpening) {
    // Opening a FIFO would block until a writer came, and a device never ends: both are
    // refused from the file's status alone, so this test returns at once.
    ScratchFolder folder;
    const std::filesystem::path fifo = folder.path() / "pipe.off";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    EXPECT_NE(mesh_error(fifo).find("a FIFO, not a regular file"), std::string::npos)
        << mesh_error(fifo);
    EXPECT_NE(mesh_error("/dev/zero").find("a device, not a regular file"), std::string::npos);
    EXPECT_NE(mesh_error("/dev/urandom").find("a device"), std::string::npos);
    EXPECT_NE(mesh_error(folder.path()).find("a directory"), std::string::npos);
    // std::filesystem keeps the NUL; the C library would open "box" and stop there.
    const std::string with_nul = (kFixtures / "box").string() + std::string(1, '\0') + ".off";
    EXPECT_NE(mesh_error(with_nul).find("NUL byte"), std::string::npos) << mesh_error(with_nul);
}

TEST(MeshIo, ALineLongerThanOneMebibyteIsRefusedWithoutReadingTheRest) {
    ScratchFolder folder;
    const std::filesystem::path path = folder.path() / "long.obj";
    {
        std::ofstream out(path, std::ios::binary);
        out << "v 0 0 0\n# " << std::string(3u << 20, 'x');  // 3 MiB, no newline
    }
    const std::string message = mesh_error(path);
    EXPECT_NE(message.find("line 2: longer than 1048576 bytes"), std::string::npos) << message;
}

/// Writes `text` to `path` and checks that it loads as the fixture box_ascii.ply does: the same
/// vertices, triangles and face count (`label` names the case). Returns the load's report.
MeshReport expect_loads_as_the_ply_box(const std::string& text, const std::filesystem::path& path,
                                       const std::string& label) {
    std::ofstream(path, std::ios::binary) << text;
    MeshReport report, reference;
    const TriangleMeshData mesh = load_mesh(path, &report);
    const TriangleMeshData expected = load_mesh(kFixtures / "box_ascii.ply", &reference);
    EXPECT_EQ(mesh.vertices, expected.vertices) << label;
    EXPECT_EQ(mesh.triangles, expected.triangles) << label;
    EXPECT_EQ(report.faces, reference.faces) << label;
    return report;
}

TEST(MeshIo, PlyFormatVersionOneWithoutDecimalsLoadsAsTheToolsReadIt) {
    // "format ascii 1" is what some exporters write; OpenMesh and assimp read it as 1.0.
    ScratchFolder folder;
    std::string text = test::file_contents(kFixtures / "box_ascii.ply");
    const std::size_t at = text.find("format ascii 1.0");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 16, "format ascii 1");
    const std::filesystem::path path = folder.path() / "box.ply";
    expect_loads_as_the_ply_box(text, path, "format ascii 1");
    // Other versions stay refused: the format has only 1.0.
    text.replace(at, 14, "format ascii 2");
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
    EXPECT_NE(mesh_error(path).find("expected 'format <type> 1.0'"), std::string::npos);
}

TEST(MeshIo, PlyHeaderLinesTheToolsTolerateLoadAsTheFixture) {
    // What exporters write and OpenMesh and assimp read (docs/meshes.md): obj_info and
    // comment lines anywhere in the header, blank header lines, CRLF line ends throughout.
    ScratchFolder folder;
    std::istringstream lines(test::file_contents(kFixtures / "box_ascii.ply"));
    std::string text;
    for (std::string line; std::getline(lines, line);) {
        text += line + "\r\n";
        if (line.rfind("format ", 0) == 0) text += "obj_info written by a test\r\n\r\n";
        if (line.rfind("element face", 0) == 0) text += "comment between elements\r\n";
    }
    const MeshReport report =
        expect_loads_as_the_ply_box(text, folder.path() / "box.ply", "tolerated header lines");
    EXPECT_TRUE(report.is_closed);
}

TEST(MeshIo, AsciiStlWithSeveralSolidsIsOneMesh) {
    // The fixture's 12 facets, then the same box moved by 10 in x as a second solid: 24
    // triangles, two closed components, as exporters write several parts.
    ScratchFolder folder;
    const std::string box = test::file_contents(kFixtures / "box_ascii.stl");
    std::string moved;
    std::istringstream lines(box);
    for (std::string line; std::getline(lines, line);) {
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (keyword == "vertex") {
            double x, y, z;
            words >> x >> y >> z;
            std::ostringstream shifted;
            shifted << "      vertex " << x + 10 << ' ' << y << ' ' << z;
            line = shifted.str();
        }
        moved += line + "\n";
    }
    const std::filesystem::path path = folder.path() / "two.stl";
    std::ofstream(path, std::ios::binary) << box << "\n" << moved;
    MeshReport report;
    const TriangleMeshData mesh = load_mesh(path, &report);
    EXPECT_EQ(report.faces, 24u);
    EXPECT_EQ(mesh.triangles.size(), 24u);
    EXPECT_EQ(report.components, 2u);
    EXPECT_TRUE(report.is_closed);
    // Something else after 'endsolid' is still refused, at its line.
    std::ofstream(path, std::ios::binary | std::ios::trunc) << box << "facet normal 0 0 1\n";
    EXPECT_NE(mesh_error(path).find("expected 'solid' or the end of the file"), std::string::npos)
        << mesh_error(path);
}

TEST(MeshIo, OpenMeshPrintsNothing) {
    // box_quads.obj names a material library that does not exist, which OpenMesh's OBJ reader
    // reports on its error stream; a non-manifold mesh makes its half-edge mesh complain too.
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    load_mesh(kFixtures / "box_quads.obj");
    const TriangleMeshData fin{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                               {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}},
                               {}};
    EXPECT_THROW(loop_subdivide(fin, 1), InvalidParameter);
    const std::string printed =
        ::testing::internal::GetCapturedStderr() + ::testing::internal::GetCapturedStdout();
    EXPECT_EQ(printed, "");
}

TEST(MeshIo, SavedBinaryPlyLoadsBackIdentically) {
    const TriangleMeshData original = load_mesh(kFixtures / "box_ascii.ply");
    const std::filesystem::path path =
        std::filesystem::path(CSGRT_BINARY_DIR) / "mesh_io_round_trip.ply";
    save_mesh(path, original);
    MeshReport report;
    const TriangleMeshData reloaded = load_mesh(path, &report);
    EXPECT_TRUE(report.binary);
    EXPECT_EQ(reloaded.vertices, original.vertices);
    EXPECT_EQ(reloaded.triangles, original.triangles);
    EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial"));
    std::filesystem::remove(path);
    EXPECT_THROW(save_mesh(kFixtures / "no_such_folder" / "x.ply", original), MeshError);
}

// Validation of meshes made in memory.

TEST(ValidateMesh, ClosedCubeNeedsNoRepair) {
    TriangleMeshData cube = to_data(test::integer_cube(3));
    const auto original = cube.triangles;
    const MeshReport report = validate_mesh(cube);
    EXPECT_TRUE(report.is_closed);
    EXPECT_EQ(report.components, 1u);
    EXPECT_EQ(report.edges, 3 * original.size() / 2);
    EXPECT_EQ(report.flipped_triangles, 0u);
    EXPECT_EQ(cube.triangles, original);
    EXPECT_DOUBLE_EQ(report.volume, 27.0);
}

TEST(ValidateMesh, InconsistentTrianglesAreTurnedToAgreeWithTheMajority) {
    TriangleMeshData cube = to_data(test::integer_cube(3));
    const auto original = cube.triangles;
    std::size_t turned = 0;
    for (std::size_t i = 0; i < cube.triangles.size(); i += 7, ++turned) {
        std::swap(cube.triangles[i][1], cube.triangles[i][2]);
    }
    const MeshReport report = validate_mesh(cube);
    EXPECT_GT(report.inconsistent_edges, 0u);
    EXPECT_EQ(report.flipped_triangles, turned);
    EXPECT_EQ(report.inverted_components, 0u);
    EXPECT_TRUE(report.is_closed);
    EXPECT_EQ(cube.triangles, original);
}

TEST(ValidateMesh, InsideOutMeshIsTurnedOutward) {
    TriangleMeshData sphere = to_data(test::sphere_mesh(2));
    const auto original = sphere.triangles;
    for (auto& t : sphere.triangles) std::swap(t[1], t[2]);
    const MeshReport report = validate_mesh(sphere);
    EXPECT_EQ(report.inconsistent_edges, 0u);
    EXPECT_EQ(report.inverted_components, 1u);
    EXPECT_EQ(report.flipped_triangles, original.size());
    EXPECT_EQ(sphere.triangles, original);
    EXPECT_GT(report.volume, 0.0);
}

TEST(ValidateMesh, NestedShellsKeepTheirCavity) {
    // A 6-cube with a 2-cube cavity: the cavity's triangles must face into the cavity (away
    // from the solid), whichever way the input wound them.
    const test::TestMesh outer = test::integer_cube(6);
    test::TestMesh inner = test::integer_cube(2);
    for (auto& v : inner.vertices) v += Eigen::Vector3d(2, 2, 2);
    for (bool inner_outward : {true, false}) {
        TriangleMeshData mesh = to_data(outer);
        const auto offset = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.insert(mesh.vertices.end(), inner.vertices.begin(), inner.vertices.end());
        for (auto t : inner.triangles) {
            if (!inner_outward) std::swap(t[1], t[2]);
            mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
        }
        const MeshReport report = validate_mesh(mesh);
        EXPECT_EQ(report.components, 2u);
        EXPECT_TRUE(report.is_closed);
        EXPECT_DOUBLE_EQ(report.volume, 216.0 - 8.0);
        EXPECT_EQ(report.inverted_components, inner_outward ? 1u : 0u);
        // Every cavity triangle's normal points toward the cavity's centre (3, 3, 3).
        for (std::size_t i = outer.triangles.size(); i < mesh.triangles.size(); ++i) {
            const auto& t = mesh.triangles[i];
            const Eigen::Vector3d centroid =
                (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.0;
            EXPECT_LT(face_normal(mesh, t).dot(centroid - Eigen::Vector3d(3, 3, 3)), 0.0);
        }
    }
}

TEST(ValidateMesh, OpenNonManifoldAndNonOrientableMeshesAreNotSolids) {
    TriangleMeshData open = to_data(test::integer_cube(2));
    open.triangles.pop_back();
    MeshReport report = validate_mesh(open);
    EXPECT_EQ(report.boundary_edges, 3u);
    EXPECT_FALSE(report.is_closed);

    // Three triangles on one edge (0, 1).
    TriangleMeshData fin{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                         {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}},
                         {}};
    report = validate_mesh(fin);
    EXPECT_EQ(report.non_manifold_edges, 1u);
    EXPECT_EQ(report.boundary_edges, 6u);
    EXPECT_FALSE(report.is_closed);

    // A Moebius strip of 6 triangles: no consistent winding exists.
    TriangleMeshData strip;
    const int n = 3;
    for (int i = 0; i < n; ++i) {
        const double angle = kTwoPi * i / n;
        const Eigen::Vector3d center(std::cos(angle), std::sin(angle), 0);
        const Eigen::Vector3d across =
            std::cos(angle / 2) * center + std::sin(angle / 2) * Eigen::Vector3d::UnitZ();
        strip.vertices.push_back(center + 0.3 * across);
        strip.vertices.push_back(center - 0.3 * across);
    }
    for (int i = 0; i < n; ++i) {
        const auto a = static_cast<std::uint32_t>(2 * i), b = a + 1;
        // The last quad joins the strip to its start with the sides swapped: the half twist.
        const std::uint32_t c = i + 1 < n ? a + 2 : 1, d = i + 1 < n ? a + 3 : 0;
        strip.triangles.push_back({a, b, d});
        strip.triangles.push_back({a, d, c});
    }
    report = validate_mesh(strip);
    EXPECT_FALSE(report.orientable);
    EXPECT_FALSE(report.is_closed);
}

TEST(ValidateMesh, DegenerateTrianglesAreDroppedAndCounted) {
    TriangleMeshData mesh = to_data(test::integer_cube(1));
    const std::size_t good = mesh.triangles.size();
    auto index_of = [&](const Eigen::Vector3d& p) {
        const auto it = std::find(mesh.vertices.begin(), mesh.vertices.end(), p);
        return static_cast<std::uint32_t>(it - mesh.vertices.begin());
    };
    const std::uint32_t origin = index_of({0, 0, 0}), x = index_of({1, 0, 0});
    mesh.vertices.push_back({0.5, 0, 0});  // on the cube edge from origin to x
    mesh.vertices.push_back({9, 9, 9});    // used by nothing
    const auto on_edge = static_cast<std::uint32_t>(mesh.vertices.size() - 2);
    mesh.triangles.push_back({origin, origin, x});   // repeated corner
    mesh.triangles.push_back({origin, on_edge, x});  // collinear corners, zero area
    const MeshReport report = validate_mesh(mesh);
    EXPECT_EQ(report.degenerate_triangles, 2u);
    EXPECT_EQ(report.triangles, good);
    EXPECT_EQ(mesh.triangles.size(), good);
    EXPECT_EQ(report.unreferenced_vertices, 2u);
    EXPECT_EQ(mesh.normals[on_edge], Eigen::Vector3d::Zero());
}

TEST(ValidateMesh, RejectsNonFiniteVerticesBadIndicesAndEmptyMeshes) {
    TriangleMeshData nan_vertex = to_data(test::integer_cube(1));
    nan_vertex.vertices[3].y() = std::nan("");
    EXPECT_THROW(validate_mesh(nan_vertex), InvalidParameter);
    TriangleMeshData bad_index = to_data(test::integer_cube(1));
    bad_index.triangles[5][2] = 8;
    EXPECT_THROW(validate_mesh(bad_index), InvalidParameter);
    TriangleMeshData empty{{{0, 0, 0}}, {}, {}};
    EXPECT_THROW(validate_mesh(empty), InvalidParameter);
    TriangleMeshData flat{{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, {{0, 1, 2}}, {}};
    EXPECT_THROW(validate_mesh(flat), InvalidParameter);
}

TEST(ValidateMesh, VertexNormalsOfASphereMeshPointOutward) {
    TriangleMeshData sphere = to_data(test::sphere_mesh(3));
    validate_mesh(sphere);
    for (std::size_t v = 0; v < sphere.vertices.size(); ++v) {
        EXPECT_NEAR(sphere.normals[v].norm(), 1.0, 1e-15);
        // The vertices lie on the unit sphere; the normal follows it to within the
        // tessellation's angle (edges of about 0.2 rad at 3 levels).
        EXPECT_GT(sphere.normals[v].dot(sphere.vertices[v]), std::cos(0.1)) << v;
    }
}

// The real meshes extracted by data/fetch-meshes, with the counts their OFF headers declare.
struct RealMesh {
    const char* name;
    std::size_t vertices;
    std::size_t triangles;
    bool closed;
    int genus;  // of the closed ones: handles (the elephants' tusks and trunk make 3)
};

void PrintTo(const RealMesh& mesh, std::ostream* out) {
    *out << mesh.name;
}

class RealMeshes : public ::testing::TestWithParam<RealMesh> {};

TEST_P(RealMeshes, LoadWithTheirDeclaredCounts) {
    const RealMesh& expected = GetParam();
    const std::filesystem::path path = test::real_mesh(expected.name);
    if (path.empty()) GTEST_SKIP() << "data/fetch-meshes could not provide " << expected.name;
    MeshReport report;
    const TriangleMeshData mesh = load_mesh(path, &report);
    EXPECT_EQ(mesh.vertices.size(), expected.vertices);
    EXPECT_EQ(mesh.triangles.size(), expected.triangles);
    EXPECT_EQ(report.degenerate_triangles, 0u);
    EXPECT_EQ(report.is_closed, expected.closed) << describe(report);
    // Every triangle has three edges and every interior edge two triangles.
    EXPECT_EQ(2 * report.edges - report.boundary_edges, 3 * report.triangles);
    if (expected.closed) {
        EXPECT_GT(report.volume, 0.0);
        // Euler: V - E + F = 2 - 2 genus for a closed connected surface.
        EXPECT_EQ(static_cast<long>(report.vertices) - static_cast<long>(report.edges) +
                      static_cast<long>(report.triangles),
                  2 - 2 * expected.genus);
        EXPECT_EQ(report.components, 1u);
    }
    for (const Eigen::Vector3d& normal : mesh.normals) EXPECT_NEAR(normal.norm(), 1.0, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(DataMeshes, RealMeshes,
                         ::testing::Values(RealMesh{"armadillo", 26002, 52000, true, 0},
                                           RealMesh{"ChineseDragon-10kv", 10000, 19994, false, 0},
                                           RealMesh{"bunny00", 37706, 75408, true, 0},
                                           RealMesh{"elephant", 2775, 5558, true, 3},
                                           RealMesh{"refined_elephant", 44460, 88928, true, 3},
                                           RealMesh{"cow", 2904, 5804, true, 0},
                                           RealMesh{"fandisk", 6475, 12946, true, 0}),
                         [](const auto& info) {
                             std::string name = info.param.name;
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

}  // namespace
}  // namespace csgrt
