#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace csgrt {

/// Thrown when a mesh file cannot be used: missing, unreadable, corrupt, truncated, counts that
/// disagree with the data, out-of-range indices, non-finite coordinates, no triangles. The
/// message starts with the file's path and says what is wrong, with the line (text formats) or
/// the element (binary formats) where it can: "a.off: line 7: face 1 refers to vertex 9, but
/// the file has 4 vertices".
class MeshError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// An indexed triangle mesh in double precision: what the loader, the mesh tools and the Mesh
/// shape exchange. Triangles wind counter-clockwise seen from the side their normal points to.
struct TriangleMeshData {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    /// Unit per-vertex normals for smooth shading, angle-weighted (Thuermer and Wuethrich,
    /// "Computing Vertex Normals from Polygonal Facets", JGT 3(1) 1998); zero for a vertex no
    /// triangle uses or whose triangles' normals cancel. Filled by `validate_mesh` (and so by
    /// `load_mesh`).
    std::vector<Eigen::Vector3d> normals;
    /// Normals the file stores (OBJ `vn` by face corner, PLY `nx ny nz` and NOFF by vertex),
    /// one per triangle corner in the order of `triangles`, unit or zero; empty when the file
    /// has none, or not for every corner. A Mesh shades with them instead of `normals`
    /// (MeshConfig::file_normals). validate_mesh keeps them with their triangles.
    std::vector<std::array<Eigen::Vector3f, 3>> corner_normals = {};
};

/// What loading and validation found and repaired (docs/meshes.md lists the rules).
struct MeshReport {
    /// "off", "obj", "ply" or "stl" (empty for meshes made in memory), and whether the file
    /// was binary.
    std::string format;
    bool binary = false;
    /// Faces as the file stores them (polygons or triangles, STL facets).
    std::size_t faces = 0;
    /// Faces the reader dropped because fewer than 3 of their corners are distinct (OpenMesh's
    /// OBJ and STL readers do this; other degenerate faces are counted as triangles below).
    std::size_t dropped_faces = 0;
    /// Faces with more than 3 corners, split into triangles by ear clipping.
    std::size_t triangulated_faces = 0;
    /// Of those, faces that are not simple polygons (their edges cross, or they collapse onto
    /// a line): ear clipping cut them at the crossings or split what it could not clip as a fan
    /// from one corner, so their triangles' area may differ from the polygon's. A keyhole (a
    /// hole joined by a bridge whose corners repeat) is simple enough and is not counted.
    std::size_t non_simple_faces = 0;
    /// Whether the file gave a normal for every corner (TriangleMeshData::corner_normals).
    bool file_normals = false;
    /// Vertices merged into another at the same position (MeshConfig::weld_vertices).
    std::size_t welded_vertices = 0;
    std::size_t vertices = 0;
    /// Triangles kept, after degenerate ones were dropped.
    std::size_t triangles = 0;
    /// Zero-area triangles (repeated corners or collinear corners), dropped.
    std::size_t degenerate_triangles = 0;
    /// Vertices no kept triangle uses (kept in the vertex list, with a zero normal).
    std::size_t unreferenced_vertices = 0;
    /// Undirected edges of the triangles, and how many of them have one triangle (boundary),
    /// more than two (non-manifold), or two that traverse it in the same direction
    /// (inconsistently oriented, as read).
    std::size_t edges = 0;
    std::size_t boundary_edges = 0;
    std::size_t non_manifold_edges = 0;
    std::size_t inconsistent_edges = 0;
    /// Edge-connected pieces of the surface.
    std::size_t components = 0;
    /// False when no choice of winding makes every edge consistent (a Moebius strip).
    bool orientable = true;
    /// Triangles whose winding was reversed on load: the fewer-triangles side of each
    /// inconsistent component, then whole closed shells that faced inward.
    std::size_t flipped_triangles = 0;
    /// Closed shells that faced inward and were turned outward (their triangles are counted
    /// above).
    std::size_t inverted_components = 0;
    /// No boundary and no non-manifold edge, and orientable: a solid, oriented outward, so the
    /// Mesh shape answers spans and point membership. (Self-intersections are not checked.)
    bool is_closed = false;
    /// Enclosed volume after orientation (closed meshes; 0 otherwise).
    double volume = 0.0;
};

/// Reads an OFF, OBJ, PLY (ascii or binary) or STL (ascii or binary) file through OpenMesh's
/// readers, after checking the file's structure independently (OpenMesh accepts truncated and
/// miscounted files silently), then triangulates polygons, validates and repairs the result
/// with `validate_mesh`. Coordinates arrive in float, as OpenMesh 9's readers deliver them.
/// OpenMesh prints nothing meanwhile (its message streams are disabled). Throws MeshError
/// naming the file and the problem; never returns partial data. Thread-safe (OpenMesh's
/// readers are not, so the OpenMesh part of loads is serialised).
TriangleMeshData load_mesh(const std::filesystem::path& path, MeshReport* report = nullptr);

/// Validates and repairs a mesh made in memory by the rules load_mesh applies after reading:
/// drops degenerate triangles, finds boundary, non-manifold and inconsistent edges, orients
/// orientable components consistently and closed shells outward, computes vertex normals.
/// Throws InvalidParameter for a non-finite vertex, an out-of-range index, or no triangle left.
MeshReport validate_mesh(TriangleMeshData& mesh);

/// validate_mesh again on a mesh read from a file (after triangulating it or welding its
/// vertices): the report keeps from `as_read` what only reading the file could find, its format
/// and its faces as stored, dropped, triangulated and not simple.
MeshReport validate_mesh(TriangleMeshData& mesh, const MeshReport& as_read);

/// Writes `mesh` as binary little-endian PLY (float coordinates, int indices): the cache
/// format of the mesh generator. Throws MeshError when the file cannot be written.
void save_mesh(const std::filesystem::path& path, const TriangleMeshData& mesh);

/// One line summarising a report: counts, repairs, closedness.
std::string describe(const MeshReport& report);

}  // namespace csgrt
