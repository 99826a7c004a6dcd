#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "csgrt/core/math.h"

namespace csgrt::test {

/// An indexed triangle mesh built in code, for tests that need closed meshes without files.
struct TestMesh {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// The surface of the cube [0, n]^3 cut into n x n squares per face, each split into two
/// triangles: closed, consistently oriented (outward), with integer coordinates so every
/// vertex and edge midpoint (after scaling by 2) is exactly representable.
inline TestMesh integer_cube(int n) {
    TestMesh mesh;
    std::map<std::array<int, 3>, std::uint32_t> index_of;
    auto vertex = [&](int x, int y, int z) {
        const std::array<int, 3> key{x, y, z};
        auto [it, inserted] =
            index_of.emplace(key, static_cast<std::uint32_t>(mesh.vertices.size()));
        if (inserted) mesh.vertices.emplace_back(x, y, z);
        return it->second;
    };
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
            const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
            for (int i = 0; i < n; ++i) {
                for (int j = 0; j < n; ++j) {
                    auto corner = [&](int di, int dj) {
                        std::array<int, 3> p{};
                        p[axis] = side * n;
                        p[u_axis] = i + di;
                        p[v_axis] = j + dj;
                        return vertex(p[0], p[1], p[2]);
                    };
                    const std::uint32_t a = corner(0, 0), b = corner(1, 0), c = corner(1, 1),
                                        d = corner(0, 1);
                    // u x v points along +axis; flip the winding on the low side so normals
                    // face outward.
                    if (side == 1) {
                        mesh.triangles.push_back({a, b, c});
                        mesh.triangles.push_back({a, c, d});
                    } else {
                        mesh.triangles.push_back({a, c, b});
                        mesh.triangles.push_back({a, d, c});
                    }
                }
            }
        }
    }
    return mesh;
}

/// A unit sphere approximated by subdividing an octahedron `levels` times and projecting the
/// vertices onto the sphere: closed, 8 * 4^levels triangles, with irrational coordinates.
inline TestMesh sphere_mesh(int levels) {
    TestMesh mesh;
    mesh.vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                      {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint_of;
        auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            auto it = midpoint_of.find(key);
            if (it != midpoint_of.end()) return it->second;
            mesh.vertices.push_back((mesh.vertices[a] + mesh.vertices[b]).normalized());
            const auto index = static_cast<std::uint32_t>(mesh.vertices.size() - 1);
            midpoint_of.emplace(key, index);
            return index;
        };
        std::vector<std::array<std::uint32_t, 3>> finer;
        for (const auto& [a, b, c] : mesh.triangles) {
            const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            finer.push_back({a, ab, ca});
            finer.push_back({ab, b, bc});
            finer.push_back({ca, bc, c});
            finer.push_back({ab, bc, ca});
        }
        mesh.triangles = std::move(finer);
    }
    return mesh;
}

}  // namespace csgrt::test
