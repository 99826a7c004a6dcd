#include "csgrt/mesh/mesh_tools.h"

// OpenMesh's properties default-construct their vectors uninitialised by design; GCC's
// -Wmaybe-uninitialized flags that inside its headers at -O1 (the asan preset). Clang has no
// such warning, and -Werror turns the unknown name into an error (the fuzz preset).
#pragma GCC diagnostic push
#if !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "csgrt/core/error.h"
#include "openmesh_session.h"

namespace csgrt {

namespace {

/// Double-precision points, so subdivision and decimation add no float rounding of their own.
struct DoubleTraits : OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
};
using HalfEdgeMesh = OpenMesh::TriMesh_ArrayKernelT<DoubleTraits>;

/// The referenced vertices and the triangles of `mesh` as a half-edge mesh.
HalfEdgeMesh to_half_edges(const TriangleMeshData& mesh, std::string_view what) {
    constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> handle_of(mesh.vertices.size(), kUnused);
    HalfEdgeMesh result;
    result.reserve(static_cast<unsigned>(mesh.vertices.size()),
                   static_cast<unsigned>(3 * mesh.triangles.size() / 2),
                   static_cast<unsigned>(mesh.triangles.size()));
    // add_face prints "complex edge" for each face it refuses; the refusal is thrown instead.
    detail::OpenMeshSession session;
    std::vector<HalfEdgeMesh::VertexHandle> corners(3);
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = mesh.triangles[i][k];
            if (v >= mesh.vertices.size()) {
                require(false, what, "triangle " + std::to_string(i),
                        "indices below the vertex count", v);
            }
            if (handle_of[v] == kUnused) {
                const Eigen::Vector3d& p = mesh.vertices[v];
                handle_of[v] = static_cast<std::uint32_t>(
                    result.add_vertex(HalfEdgeMesh::Point(p.x(), p.y(), p.z())).idx());
            }
            corners[k] = HalfEdgeMesh::VertexHandle(static_cast<int>(handle_of[v]));
        }
        if (result.add_face(corners).is_valid()) continue;
        require(false, what, "triangle " + std::to_string(i),
                "manifold (OpenMesh's half-edge mesh refused it: a non-manifold edge or vertex, "
                "or a repeated corner)",
                "refused");
    }
    return result;
}

/// The half-edge mesh's triangles back as validated indexed data.
TriangleMeshData from_half_edges(HalfEdgeMesh& half_edges, MeshReport* report) {
    half_edges.garbage_collection();
    TriangleMeshData mesh;
    mesh.vertices.reserve(half_edges.n_vertices());
    for (const auto vertex : half_edges.vertices()) {
        const HalfEdgeMesh::Point& p = half_edges.point(vertex);
        mesh.vertices.emplace_back(p[0], p[1], p[2]);
    }
    mesh.triangles.reserve(half_edges.n_faces());
    for (const auto face : half_edges.faces()) {
        std::array<std::uint32_t, 3> triangle{};
        int k = 0;
        for (const auto vertex : half_edges.fv_range(face)) {
            triangle[k++] = static_cast<std::uint32_t>(vertex.idx());
        }
        mesh.triangles.push_back(triangle);
    }
    MeshReport validation = validate_mesh(mesh);
    if (report != nullptr) *report = std::move(validation);
    return mesh;
}

}  // namespace

TriangleMeshData loop_subdivide(const TriangleMeshData& mesh, int levels, MeshReport* report) {
    require(levels >= 0 && levels <= 8, "loop_subdivide", "levels", "in [0, 8]", levels);
    constexpr double kLargest = double(std::size_t{1} << 28);
    require(double(mesh.triangles.size()) * std::pow(4.0, levels) <= kLargest, "loop_subdivide",
            "the result's triangle count", "at most 2^28", mesh.triangles.size() << (2 * levels));
    HalfEdgeMesh half_edges = to_half_edges(mesh, "loop_subdivide");
    if (levels > 0) {
        OpenMesh::Subdivider::Uniform::LoopT<HalfEdgeMesh> loop;
        loop.attach(half_edges);
        loop(static_cast<std::size_t>(levels));
        loop.detach();
    }
    return from_half_edges(half_edges, report);
}

TriangleMeshData decimate(const TriangleMeshData& mesh, std::size_t target_triangles,
                          MeshReport* report) {
    require(target_triangles >= 4, "decimate", "target_triangles", ">= 4", target_triangles);
    if (mesh.triangles.size() <= target_triangles) {
        TriangleMeshData copy = mesh;
        MeshReport validation = validate_mesh(copy);
        if (report != nullptr) *report = std::move(validation);
        return copy;
    }
    HalfEdgeMesh half_edges = to_half_edges(mesh, "decimate");
    {
        using Decimater = OpenMesh::Decimater::DecimaterT<HalfEdgeMesh>;
        using Quadric = OpenMesh::Decimater::ModQuadricT<HalfEdgeMesh>::Handle;
        using NormalFlipping = OpenMesh::Decimater::ModNormalFlippingT<HalfEdgeMesh>::Handle;
        // Requested here as well as by the Decimater, which releases them when it goes: the
        // deleted flags must outlive it for garbage collection.
        half_edges.request_vertex_status();
        half_edges.request_edge_status();
        half_edges.request_face_status();
        half_edges.request_face_normals();
        half_edges.update_face_normals();
        Decimater decimater(half_edges);
        Quadric quadric;
        decimater.add(quadric);
        decimater.module(quadric).unset_max_err();  // the quadric orders; it never vetoes
        NormalFlipping flipping;
        decimater.add(flipping);
        decimater.module(flipping).set_max_normal_deviation(60.0);
        require(decimater.initialize(), "decimate", "modules", "initialised", "false");
        decimater.decimate_to_faces(0, target_triangles);
    }
    return from_half_edges(half_edges, report);
}

std::size_t weld_vertices(TriangleMeshData& mesh) {
    const std::size_t count = mesh.vertices.size();
    std::vector<std::uint32_t> order(count);
    for (std::size_t i = 0; i < count; ++i) order[i] = static_cast<std::uint32_t>(i);
    // Lexicographic order of the positions, ties by index, so each group of equal positions
    // is contiguous and keeps its first vertex.
    auto less = [&](std::uint32_t a, std::uint32_t b) {
        const Eigen::Vector3d &p = mesh.vertices[a], &q = mesh.vertices[b];
        if (p.x() != q.x()) return p.x() < q.x();
        if (p.y() != q.y()) return p.y() < q.y();
        if (p.z() != q.z()) return p.z() < q.z();
        return a < b;
    };
    std::sort(order.begin(), order.end(), less);
    std::vector<std::uint32_t> representative(count);
    for (std::size_t k = 0; k < count; ++k) {
        const bool same = k > 0 && mesh.vertices[order[k]] == mesh.vertices[order[k - 1]];
        representative[order[k]] = same ? representative[order[k - 1]] : order[k];
    }
    // Renumber the kept vertices in their original order.
    std::vector<std::uint32_t> new_index(count, std::numeric_limits<std::uint32_t>::max());
    std::vector<Eigen::Vector3d> kept;
    for (std::size_t i = 0; i < count; ++i) {
        if (representative[i] != i) continue;
        new_index[i] = static_cast<std::uint32_t>(kept.size());
        kept.push_back(mesh.vertices[i]);
    }
    for (auto& triangle : mesh.triangles) {
        for (std::uint32_t& corner : triangle) corner = new_index[representative[corner]];
    }
    const std::size_t merged = count - kept.size();
    mesh.vertices = std::move(kept);
    mesh.normals.clear();
    return merged;
}

}  // namespace csgrt
