#pragma once

#include <memory>
#include <utility>

#include "csgrt/core/shape.h"
#include "csgrt/core/transform.h"
#include "csgrt/mesh/mesh.h"
#include "support/meshes.h"

namespace csgrt::test {

/// `mesh` with every vertex mapped by `placement` (in world space, not under an Instance), as
/// a float Mesh or, with `double_precision`, a double one.
inline std::shared_ptr<const Shape> mesh_at(const TestMesh& mesh, const Transform& placement,
                                            bool double_precision) {
    TriangleMeshData data{mesh.vertices, mesh.triangles, {}};
    for (Eigen::Vector3d& v : data.vertices) v = placement.apply_point(v);
    MeshConfig config;
    config.double_precision = double_precision;
    return std::make_shared<Mesh>(std::move(data), config);
}

}  // namespace csgrt::test
