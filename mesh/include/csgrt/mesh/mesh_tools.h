#pragma once

#include <cstddef>

#include "csgrt/mesh/mesh_io.h"

namespace csgrt {

/// Loop subdivision (Loop, "Smooth Subdivision Surfaces Based on Triangles", MS thesis, Utah,
/// 1987) through OpenMesh: each level splits every triangle into four and moves the vertices
/// toward the limit surface, so a closed manifold stays closed with 4^levels times the
/// triangles. Returns a validated mesh (validate_mesh; `report` receives its report). Throws
/// InvalidParameter for levels outside [0, 8], a result above 2^28 triangles, or a mesh that
/// a half-edge structure cannot hold (a non-manifold edge or vertex).
TriangleMeshData loop_subdivide(const TriangleMeshData& mesh, int levels,
                                MeshReport* report = nullptr);

/// Quadric error metric simplification (Garland and Heckbert, "Surface Simplification Using
/// Quadric Error Metrics", SIGGRAPH 1997) through OpenMesh's Decimater, with collapses that
/// would flip a face's normal by more than 60 degrees refused. Stops at `target_triangles`
/// (a collapse removes two triangles, so it may land one above) or when no allowed collapse
/// is left. A mesh already at or below the target is returned validated but unchanged.
/// Throws InvalidParameter for a target below 4 or a mesh a half-edge structure cannot hold.
TriangleMeshData decimate(const TriangleMeshData& mesh, std::size_t target_triangles,
                          MeshReport* report = nullptr);

/// Merges vertices at the same position (every coordinate equal: a soup written one vertex
/// per corner, as exporters do for per-corner normals or colours) into one, so that triangles
/// that meet share their edges and a closed surface is recognised as a solid. Returns how many
/// vertices were merged away; the triangles are renumbered, unreferenced copies removed, and
/// the normals cleared (run validate_mesh afterwards, which recomputes them and the topology).
/// Linear in the vertices after a sort. Positions equal only to within a rounding are not
/// merged: a tolerance would join vertices a model means to keep apart.
std::size_t weld_vertices(TriangleMeshData& mesh);

}  // namespace csgrt
