#include "csgrt/mesh/mesh_io.h"

#include <Eigen/Geometry>
#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/IO/reader/OBJReader.hh>
#include <OpenMesh/Core/IO/reader/OFFReader.hh>
#include <OpenMesh/Core/IO/reader/PLYReader.hh>
#include <OpenMesh/Core/IO/reader/STLReader.hh>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <span>
#include <sstream>
#include <streambuf>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <vector>

#include "csgrt/core/error.h"
#include "mesh_scan.h"
#include "openmesh_session.h"
#include "polygon_triangulation.h"

// load_mesh: the scan (mesh_scan.h, format_*.cpp), OpenMesh's reader into a recording
// importer, the cross-check, triangulation (polygon_triangulation.h) and validation
// (mesh_validation.cpp); save_mesh and describe.

namespace csgrt {

using namespace detail;

namespace {

using Triangle = std::array<std::uint32_t, 3>;

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

/// Receives what an OpenMesh reader parses, without building a half-edge mesh (which would
/// reject non-manifold faces and so hide them from validation): vertices and polygons, raw.
class RecordingImporter final : public OpenMesh::IO::BaseImporter {
public:
    std::vector<Eigen::Vector3f> points;
    std::vector<int> corners;
    std::vector<std::size_t> face_starts;
    std::vector<Eigen::Vector3f> vertex_normals;
    std::vector<char> normal_set;
    bool bad_handle = false;

    OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
        points.emplace_back(p[0], p[1], p[2]);
        return OpenMesh::VertexHandle(static_cast<int>(points.size() - 1));
    }
    OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
        return add_vertex(OpenMesh::Vec3f(float(p[0]), float(p[1]), float(p[2])));
    }
    OpenMesh::VertexHandle add_vertex() override { return add_vertex(OpenMesh::Vec3f(0, 0, 0)); }
    void set_point(OpenMesh::VertexHandle vertex, const OpenMesh::Vec3f& p) override {
        if (vertex.idx() < 0 || static_cast<std::size_t>(vertex.idx()) >= points.size()) {
            bad_handle = true;
            return;
        }
        points[static_cast<std::size_t>(vertex.idx())] = Eigen::Vector3f(p[0], p[1], p[2]);
    }
    OpenMesh::FaceHandle add_face(const VHandles& handles) override {
        face_starts.push_back(corners.size());
        for (const OpenMesh::VertexHandle& handle : handles) corners.push_back(handle.idx());
        return OpenMesh::FaceHandle(static_cast<int>(face_starts.size() - 1));
    }
    std::size_t face_count() const { return face_starts.size(); }
    std::span<const int> face(std::size_t f) const {
        const std::size_t end = f + 1 < face_starts.size() ? face_starts[f + 1] : corners.size();
        return {corners.data() + face_starts[f], end - face_starts[f]};
    }

    // Everything else a reader may report (normals, colours, texture coordinates, status,
    // half-edge connectivity) is not needed.
    OpenMesh::HalfedgeHandle add_edge(OpenMesh::VertexHandle, OpenMesh::VertexHandle) override {
        bad_handle = true;
        return OpenMesh::HalfedgeHandle();
    }
    OpenMesh::FaceHandle add_face(OpenMesh::HalfedgeHandle) override {
        bad_handle = true;
        return OpenMesh::FaceHandle();
    }
    void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle,
                            const std::vector<OpenMesh::Vec2f>&) override {}
    void add_face_texcoords(OpenMesh::FaceHandle, OpenMesh::VertexHandle,
                            const std::vector<OpenMesh::Vec3f>&) override {}
    void set_face_texindex(OpenMesh::FaceHandle, int) override {}
    void set_halfedge(OpenMesh::VertexHandle, OpenMesh::HalfedgeHandle) override {}
    /// PLY's nx ny nz, per vertex (asked for with Options::VertexNormal).
    void set_normal(OpenMesh::VertexHandle vertex, const OpenMesh::Vec3f& n) override {
        if (!vertex.is_valid() || static_cast<std::size_t>(vertex.idx()) >= points.size()) {
            bad_handle = true;
            return;
        }
        vertex_normals.resize(points.size(), Eigen::Vector3f::Zero());
        normal_set.resize(points.size(), 0);
        vertex_normals[static_cast<std::size_t>(vertex.idx())] = Eigen::Vector3f(n[0], n[1], n[2]);
        normal_set[static_cast<std::size_t>(vertex.idx())] = 1;
    }
    void set_normal(OpenMesh::VertexHandle vertex, const OpenMesh::Vec3d& n) override {
        set_normal(vertex, OpenMesh::Vec3f(float(n[0]), float(n[1]), float(n[2])));
    }
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec3uc&) override {}
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec4uc&) override {}
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
    void set_color(OpenMesh::VertexHandle, const OpenMesh::Vec4f&) override {}
    void set_texcoord(OpenMesh::VertexHandle, const OpenMesh::Vec2f&) override {}
    void set_status(OpenMesh::VertexHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void set_next(OpenMesh::HalfedgeHandle, OpenMesh::HalfedgeHandle) override {}
    void set_face(OpenMesh::HalfedgeHandle, OpenMesh::FaceHandle) override {}
    void request_face_texcoords2D() override {}
    void set_texcoord(OpenMesh::HalfedgeHandle, const OpenMesh::Vec2f&) override {}
    void set_texcoord(OpenMesh::VertexHandle, const OpenMesh::Vec3f&) override {}
    void set_texcoord(OpenMesh::HalfedgeHandle, const OpenMesh::Vec3f&) override {}
    void set_status(OpenMesh::HalfedgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3uc&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4uc&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3f&) override {}
    void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4f&) override {}
    void set_status(OpenMesh::EdgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void set_normal(OpenMesh::FaceHandle, const OpenMesh::Vec3f&) override {}
    void set_normal(OpenMesh::FaceHandle, const OpenMesh::Vec3d&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec3uc&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec4uc&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec3f&) override {}
    void set_color(OpenMesh::FaceHandle, const OpenMesh::Vec4f&) override {}
    void set_status(OpenMesh::FaceHandle, const OpenMesh::Attributes::StatusInfo&) override {}
    void add_texture_information(int, std::string) override {}
    std::size_t n_vertices() const override { return points.size(); }
    std::size_t n_faces() const override { return face_starts.size(); }
    std::size_t n_edges() const override { return 0; }
};

/// Meshes are indexed by 32 bits and hold at most 2^30 triangles; a binary STL of 2^30
/// facets is 50 GiB, but no mesh the library can hold needs a text file beyond 4 GiB.
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{4} << 30;

[[noreturn]] void fail_file(const std::string& name, const std::string& what) {
    throw MeshError(name + ": " + what);
}

}  // namespace

TriangleMeshData load_mesh(const std::filesystem::path& path, MeshReport* report_out) {
    const std::string name = path.string();
    auto fail = [&](const std::string& what) { fail_file(name, what); };
    if (name.find('\0') != std::string::npos) {
        fail_file(shown(name), "the path contains a NUL byte, which no file name can");
    }
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (!std::filesystem::exists(status)) fail("no such file");
    if (!std::filesystem::is_regular_file(status)) {
        // Refused before opening: a FIFO would block and a device never end.
        fail(std::filesystem::is_directory(status) ? "a directory, not a regular file"
             : std::filesystem::is_fifo(status)    ? "a FIFO, not a regular file"
             : std::filesystem::is_character_file(status) || std::filesystem::is_block_file(status)
                 ? "a device, not a regular file"
                 : "not a regular file");
    }
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (error) fail("cannot read its size: " + error.message());
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (extension != ".off" && extension != ".obj" && extension != ".ply" && extension != ".stl") {
        fail("unsupported extension " + shown(extension) + " (expected .off, .obj, .ply or .stl)");
    }
    if (size == 0) fail("empty file");
    if (size > kMaxMeshFileBytes) {
        fail("the file has " + std::to_string(size) + " bytes; mesh files are at most " +
             std::to_string(kMaxMeshFileBytes) + " (4 GiB; docs/meshes.md)");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) fail("cannot open it for reading");

    MeshReport report;
    report.format = extension.substr(1);
    Expectation expect;
    try {
        if (extension == ".off") {
            expect = scan_off(in);
        } else if (extension == ".obj") {
            expect = scan_obj(in);
        } else if (extension == ".ply") {
            expect = scan_ply(in);
        } else {
            expect = scan_stl(in, size);
        }
    } catch (const FileProblem& found) {
        fail(found.what);
    }
    if (in.bad()) fail("read error");
    in.close();
    report.binary = expect.binary;
    report.faces = expect.file_faces;
    report.dropped_faces = expect.dropped_faces;

    // The file is well formed; OpenMesh parses it, and must deliver what the scan counted.
    RecordingImporter importer;
    {
        detail::OpenMeshSession session;
        OpenMesh::IO::BaseReader* reader = nullptr;
        if (extension == ".off") reader = &OpenMesh::IO::OFFReader();
        if (extension == ".obj") reader = &OpenMesh::IO::OBJReader();
        if (extension == ".ply") reader = &OpenMesh::IO::PLYReader();
        if (extension == ".stl") reader = &OpenMesh::IO::STLReader();
        // can_u_read also parses the header into the reader's options, which read() uses.
        if (!reader->can_u_read(name)) fail("OpenMesh's " + report.format + " reader refuses it");
        // Vertex normals for PLY (nx ny nz) and OFF (NOFF: x y z nx ny nz); OBJ's are per
        // corner and come from the scan.
        OpenMesh::IO::Options options;
        if (extension == ".ply" || extension == ".off")
            options += OpenMesh::IO::Options::VertexNormal;
        if (!reader->read(name, importer, options)) fail("OpenMesh could not read it");
    }
    const std::size_t face_count = importer.face_count();
    const std::size_t expected_faces = expect.file_faces - expect.dropped_faces;
    if (expected_faces == 0) fail("no face has three distinct corners");
    if (importer.bad_handle) fail("OpenMesh reported an invalid vertex handle");
    if (expect.vertices_known && importer.points.size() != expect.vertices) {
        fail("OpenMesh read " + std::to_string(importer.points.size()) +
             " vertices, the file has " + std::to_string(expect.vertices));
    }
    if (face_count != expected_faces) {
        fail("OpenMesh read " + std::to_string(face_count) + " faces, expected " +
             std::to_string(expected_faces));
    }
    std::uint64_t corners = 0, index_sum = 0;
    for (int index : importer.corners) {
        ++corners;
        index_sum += static_cast<std::uint64_t>(static_cast<long long>(index));
    }
    if (expect.corners_known && (corners != expect.corners || index_sum != expect.index_sum)) {
        fail("OpenMesh's faces disagree with the file's (corner count or indices)");
    }

    TriangleMeshData mesh;
    mesh.vertices.reserve(importer.points.size());
    for (std::size_t v = 0; v < importer.points.size(); ++v) {
        const Eigen::Vector3f& p = importer.points[v];
        if (!p.allFinite()) fail(vertex_name(v) + " has a non-finite coordinate");
        mesh.vertices.push_back(p.cast<double>());
    }
    mesh.triangles.reserve(face_count + face_count / 2);
    std::vector<std::uint32_t> polygon;
    // OBJ: the next face as the file wrote it. OpenMesh dropped those with fewer than three
    // distinct corners; the others must be OpenMesh's faces with their repeats put back.
    std::size_t written = 0;
    std::unordered_set<long long> seen;
    // The file's normals: OBJ by corner (when every corner names one), PLY and NOFF by vertex
    // (when every vertex has one). A corner's normal in a triangle of an OBJ polygon is the one
    // the polygon gave that vertex (the first, if it repeats).
    const bool obj_normals =
        !expect.written_normals.empty() &&
        std::none_of(expect.written_normals.begin(), expect.written_normals.end(),
                     [](long long index) { return index < 0; });
    const bool normals_by_vertex =
        !importer.normal_set.empty() && importer.normal_set.size() == importer.points.size() &&
        std::all_of(importer.normal_set.begin(), importer.normal_set.end(),
                    [](char set) { return set != 0; });
    std::vector<std::pair<std::uint32_t, long long>> normal_of;  // (vertex, normal), one face
    auto unit = [](const Eigen::Vector3f& n) {
        const float length = n.norm();
        return length > 0.0f && std::isfinite(length) ? Eigen::Vector3f(n / length)
                                                      : Eigen::Vector3f::Zero();
    };
    auto as_written = [&](std::size_t f) {
        for (; written < expect.written_starts.size(); ++written) {
            const std::size_t begin = expect.written_starts[written];
            const std::size_t end = written + 1 < expect.written_starts.size()
                                        ? expect.written_starts[written + 1]
                                        : expect.written_corners.size();
            seen.clear();
            std::size_t k = 0;
            bool agrees = true;
            for (std::size_t c = begin; c < end; ++c) {
                const long long index = expect.written_corners[c];
                if (!seen.insert(index).second) continue;
                agrees = agrees && k < polygon.size() && polygon[k] == index;
                ++k;
            }
            if (k < 3) continue;
            if (!agrees || k != polygon.size())
                fail("OpenMesh's " + face_name(f) + " disagrees with the file's");
            polygon.assign(expect.written_corners.begin() + static_cast<std::ptrdiff_t>(begin),
                           expect.written_corners.begin() + static_cast<std::ptrdiff_t>(end));
            if (obj_normals) {
                normal_of.clear();
                for (std::size_t c = begin; c < end; ++c) {
                    normal_of.emplace_back(static_cast<std::uint32_t>(expect.written_corners[c]),
                                           expect.written_normals[c]);
                }
                std::stable_sort(normal_of.begin(), normal_of.end(),
                                 [](const auto& a, const auto& b) { return a.first < b.first; });
            }
            ++written;
            return;
        }
        fail("OpenMesh read more faces than the file has");
    };
    for (std::size_t f = 0; f < face_count; ++f) {
        const std::span<const int> face = importer.face(f);
        if (face.size() < 3)
            fail(face_name(f) + " has " + std::to_string(face.size()) + " corners");
        polygon.clear();
        for (int index : face) {
            if (index < 0 || static_cast<std::size_t>(index) >= mesh.vertices.size()) {
                fail(face_name(f) + " refers to vertex " + std::to_string(index) +
                     ", but the file has " + std::to_string(mesh.vertices.size()) + " vertices");
            }
            polygon.push_back(static_cast<std::uint32_t>(index));
        }
        if (!expect.written_starts.empty()) as_written(f);
        report.triangulated_faces += polygon.size() > 3 ? 1 : 0;
        const std::size_t first_triangle = mesh.triangles.size();
        if (!triangulate(polygon, mesh.vertices, mesh.triangles)) ++report.non_simple_faces;
        if (!obj_normals && !normals_by_vertex) continue;
        for (std::size_t i = first_triangle; i < mesh.triangles.size(); ++i) {
            std::array<Eigen::Vector3f, 3> normals;
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t vertex = mesh.triangles[i][k];
                if (normals_by_vertex) {
                    normals[k] = unit(importer.vertex_normals[vertex]);
                    continue;
                }
                const auto found = std::lower_bound(
                    normal_of.begin(), normal_of.end(), vertex,
                    [](const auto& entry, std::uint32_t v) { return entry.first < v; });
                normals[k] = unit(expect.normals[static_cast<std::size_t>(found->second)]);
            }
            mesh.corner_normals.push_back(normals);
        }
    }
    importer = RecordingImporter();
    const std::size_t triangle_count = mesh.triangles.size();
    if (triangle_count >= (std::size_t{1} << 30) || mesh.vertices.size() >= kNone) {
        fail("too large: " + std::to_string(triangle_count) + " triangles (at most 2^30 - 1) and " +
             std::to_string(mesh.vertices.size()) + " vertices (at most 2^32 - 2)");
    }
    try {
        report = validate_mesh(mesh, report);
    } catch (const InvalidParameter&) {
        // Vertices and indices were checked above; what validation can still reject is a mesh
        // whose every triangle has zero area.
        fail("no triangle of non-zero area: all " + std::to_string(triangle_count) +
             " are degenerate");
    }
    if (report_out != nullptr) *report_out = std::move(report);
    return mesh;
}

void save_mesh(const std::filesystem::path& path, const TriangleMeshData& mesh) {
    const std::string name = path.string();
    // Written beside the target and renamed into place, so an interrupted write never leaves a
    // truncated file where a complete one is expected.
    std::filesystem::path temporary = path;
    temporary += ".partial";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) throw MeshError(name + ": cannot open for writing");
        out << "ply\nformat binary_little_endian 1.0\ncomment written by csgrt\n"
            << "element vertex " << mesh.vertices.size()
            << "\nproperty float x\nproperty float y\nproperty float z\n"
            << "element face " << mesh.triangles.size()
            << "\nproperty list uchar int vertex_indices\nend_header\n";
        auto put = [&](auto value) {
            if constexpr (std::endian::native == std::endian::big) value = byte_swapped(value);
            out.write(reinterpret_cast<const char*>(&value), sizeof value);
        };
        for (const Eigen::Vector3d& v : mesh.vertices) {
            for (int axis = 0; axis < 3; ++axis) put(static_cast<float>(v[axis]));
        }
        for (const Triangle& t : mesh.triangles) {
            put(std::uint8_t{3});
            for (std::uint32_t index : t) put(static_cast<std::int32_t>(index));
        }
        out.flush();
        if (!out) throw MeshError(name + ": write failed");
    }
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error)
        throw MeshError(name + ": cannot move the written file into place: " + error.message());
}

std::string describe(const MeshReport& report) {
    std::ostringstream out;
    if (!report.format.empty()) out << report.format << (report.binary ? " (binary)" : "") << ", ";
    out << report.vertices << " vertices, " << report.triangles << " triangles";
    if (report.faces != 0) out << " from " << report.faces << " faces";
    if (report.triangulated_faces)
        out << " (" << report.triangulated_faces << " polygons triangulated)";
    if (report.file_normals) out << ", normals from the file";
    if (report.welded_vertices) out << ", " << report.welded_vertices << " vertices welded";
    if (report.non_simple_faces) {
        out << ", " << report.non_simple_faces
            << " polygons not simple (edges cross or collapse: cut at the crossings or fanned)";
    }
    if (report.dropped_faces) out << ", " << report.dropped_faces << " faces dropped by the reader";
    if (report.degenerate_triangles)
        out << ", " << report.degenerate_triangles << " degenerate triangles dropped";
    if (report.unreferenced_vertices)
        out << ", " << report.unreferenced_vertices << " unreferenced vertices";
    out << ", " << report.components << (report.components == 1 ? " component" : " components");
    if (report.is_closed) {
        out << ", closed (volume " << report.volume << ")";
    } else {
        out << ", open: " << report.boundary_edges << " boundary and " << report.non_manifold_edges
            << " non-manifold edges" << (report.orientable ? "" : ", not orientable");
    }
    if (report.flipped_triangles) {
        out << ", " << report.flipped_triangles << " triangles re-oriented";
        if (report.inverted_components)
            out << " (" << report.inverted_components << " shells turned outward)";
    }
    return out.str();
}

}  // namespace csgrt
