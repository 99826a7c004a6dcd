#pragma once

#include "csgrt/csg/span_combine.h"
#include "csgrt/mesh/mesh_io.h"

namespace csgrt {

/// The exact reference for booleans of closed triangle meshes: CGAL's corefinement
/// (Polygon_mesh_processing::corefine_and_compute_union / _intersection / _difference) on the
/// Exact_predicates_exact_constructions_kernel, so touching and coincident faces and every new
/// edge where the surfaces cross are decided and constructed exactly. The operands' vertices
/// are taken as the doubles they are (a float mesh's operand must hold its float-rounded
/// corners); only the result's constructed vertices are rounded to double, once, at the end.
///
/// Both operands must be closed, oriented outward and free of self-intersections (the inputs
/// CGAL's corefinement requires); throws std::runtime_error naming the operand otherwise, or
/// when CGAL reports that the result is not a valid closed mesh. The result's faces are
/// triangles and its `normals` are left empty. An empty result (a regularised intersection of
/// solids that only touch) has no triangle.
TriangleMeshData cgal_mesh_boolean(BooleanOperation operation, const TriangleMeshData& first,
                                   const TriangleMeshData& second);

}  // namespace csgrt
