#include "csgrt/reference/cgal_mesh_boolean.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace csgrt {

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using VertexIndex = SurfaceMesh::Vertex_index;

SurfaceMesh to_surface_mesh(const TriangleMeshData& data, const char* which) {
    SurfaceMesh mesh;
    std::vector<VertexIndex> vertices;
    vertices.reserve(data.vertices.size());
    for (const Eigen::Vector3d& p : data.vertices) {
        vertices.push_back(mesh.add_vertex(Kernel::Point_3(p.x(), p.y(), p.z())));
    }
    for (const auto& [a, b, c] : data.triangles) {
        if (mesh.add_face(vertices.at(a), vertices.at(b), vertices.at(c)) ==
            SurfaceMesh::null_face()) {
            throw std::runtime_error(std::string("cgal_mesh_boolean: the ") + which +
                                     " operand is not a manifold surface");
        }
    }
    // Corefinement's preconditions, checked rather than assumed: a wrong operand would make
    // the reference itself wrong.
    if (!CGAL::is_closed(mesh) || PMP::does_self_intersect(mesh) ||
        !PMP::does_bound_a_volume(mesh)) {
        throw std::runtime_error(std::string("cgal_mesh_boolean: the ") + which +
                                 " operand is not a closed, outward, self-intersection-free mesh");
    }
    return mesh;
}

TriangleMeshData to_data(const SurfaceMesh& mesh) {
    TriangleMeshData data;
    std::vector<std::uint32_t> index_of(mesh.number_of_vertices() +
                                        mesh.number_of_removed_vertices());
    for (VertexIndex v : mesh.vertices()) {
        const Kernel::Point_3& p = mesh.point(v);
        index_of[v] = static_cast<std::uint32_t>(data.vertices.size());
        // The exact coordinate, rounded once.
        data.vertices.emplace_back(CGAL::to_double(p.x().exact()), CGAL::to_double(p.y().exact()),
                                   CGAL::to_double(p.z().exact()));
    }
    for (SurfaceMesh::Face_index f : mesh.faces()) {
        std::array<std::uint32_t, 3> triangle{};
        int k = 0;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) {
            if (k == 3) throw std::runtime_error("cgal_mesh_boolean: a face was not triangulated");
            triangle[k++] = index_of[v];
        }
        data.triangles.push_back(triangle);
    }
    return data;
}
}  // namespace

TriangleMeshData cgal_mesh_boolean(BooleanOperation operation, const TriangleMeshData& first,
                                   const TriangleMeshData& second) {
    // Corefinement modifies its inputs: these are the copies.
    SurfaceMesh a = to_surface_mesh(first, "first");
    SurfaceMesh b = to_surface_mesh(second, "second");
    SurfaceMesh result;
    bool valid = false;
    switch (operation) {
        case BooleanOperation::Union:
            valid = PMP::corefine_and_compute_union(a, b, result);
            break;
        case BooleanOperation::Intersection:
            valid = PMP::corefine_and_compute_intersection(a, b, result);
            break;
        case BooleanOperation::Difference:
            valid = PMP::corefine_and_compute_difference(a, b, result);
            break;
    }
    if (!valid) throw std::runtime_error("cgal_mesh_boolean: CGAL could not build the result");
    PMP::triangulate_faces(result);
    return to_data(result);
}

}  // namespace csgrt
