// validate_mesh: degenerate triangles, edge topology, orientation of components and closed
// shells, vertex normals (docs/meshes.md, "Validation").

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "csgrt/core/error.h"
#include "csgrt/mesh/mesh_io.h"

namespace csgrt {

namespace {

using Triangle = std::array<std::uint32_t, 3>;

std::string vertex_name(std::size_t index) {
    return "vertex " + std::to_string(index);
}

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kSameDirection = 1u << 31;

/// Signed volume of the tetrahedron (reference, a, b, c) times 6; positive when a, b, c wind
/// counter-clockwise seen from outside it.
double volume6(const Eigen::Vector3d& reference, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
               const Eigen::Vector3d& c) {
    return (a - reference).dot((b - reference).cross(c - reference));
}

/// Whether the ray o + t d (t > 0) crosses triangle (a, b, c): Moeller and Trumbore, "Fast,
/// Minimum Storage Ray/Triangle Intersection", JGT 2(1) 1997. Only used to find how closed
/// shells nest, once per shell at load time.
bool ray_crosses(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const Eigen::Vector3d e1 = b - a, e2 = c - a;
    const Eigen::Vector3d p = d.cross(e2);
    const double determinant = e1.dot(p);
    if (determinant == 0.0) return false;
    const double inverse = 1.0 / determinant;
    const Eigen::Vector3d s = o - a;
    const double u = s.dot(p) * inverse;
    if (u < 0.0 || u > 1.0) return false;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) * inverse;
    if (v < 0.0 || u + v > 1.0) return false;
    return e2.dot(q) * inverse > 0.0;
}

}  // namespace

MeshReport validate_mesh(TriangleMeshData& mesh) {
    constexpr std::string_view kWhat = "validate_mesh";
    auto& vertices = mesh.vertices;
    auto& triangles = mesh.triangles;
    // File normals travel with their triangles: a turned-over triangle swaps its last two
    // corners' normals too. A list that does not match the triangles is dropped.
    auto& corner_normals = mesh.corner_normals;
    if (corner_normals.size() != triangles.size()) corner_normals.clear();
    auto turn_over = [&](std::size_t f) {
        std::swap(triangles[f][1], triangles[f][2]);
        if (!corner_normals.empty()) std::swap(corner_normals[f][1], corner_normals[f][2]);
    };
    const std::size_t vertex_count = vertices.size();
    for (std::size_t v = 0; v < vertex_count; ++v) {
        if (!vertices[v].allFinite()) require(false, kWhat, vertex_name(v), "finite", vertices[v]);
    }
    require(!triangles.empty(), kWhat, "triangles", "not empty", 0);
    require(vertex_count < kNone && triangles.size() < (std::size_t{1} << 30), kWhat, "mesh size",
            "below 2^32 vertices and 2^30 triangles", triangles.size());
    for (std::size_t f = 0; f < triangles.size(); ++f) {
        for (std::uint32_t index : triangles[f]) {
            if (index >= vertex_count) {
                require(false, kWhat, "triangle " + std::to_string(f),
                        "indices below the vertex count " + std::to_string(vertex_count), index);
            }
        }
    }
    MeshReport report;
    report.vertices = vertex_count;
    const std::size_t triangle_count = triangles.size();
    auto repeated = [&](const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; };

    // Each undirected edge once: every triangle side with three distinct corners, sorted by
    // its end points, so the sides of one edge are adjacent (a sort, not a scan of the
    // triangles around a vertex per side, which is quadratic at the hub of a fan such as a
    // long polygon's triangulation). Repeated-corner triangles have no proper edges and take
    // no part in the topology; zero-area ones with distinct corners do (they may close a
    // T-junction). Manifold edges link their two triangles; the link says whether both
    // traverse the edge in the same direction (inconsistent winding).
    struct Side {
        std::uint32_t low, high, face;
        int k;
    };
    std::vector<Side> sides;
    sides.reserve(3 * triangle_count);
    for (std::size_t f = 0; f < triangle_count; ++f) {
        const Triangle& t = triangles[f];
        if (repeated(t)) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = t[k], b = t[(k + 1) % 3];
            sides.push_back({std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(f), k});
        }
    }
    std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
        if (x.low != y.low) return x.low < y.low;
        if (x.high != y.high) return x.high < y.high;
        return x.face < y.face;
    });
    std::vector<std::uint32_t> neighbour(3 * triangle_count, kNone);
    for (std::size_t begin = 0; begin < sides.size();) {
        std::size_t end = begin + 1;
        while (end < sides.size() && sides[end].low == sides[begin].low &&
               sides[end].high == sides[begin].high) {
            ++end;
        }
        const std::size_t sharing = end - begin;
        ++report.edges;
        if (sharing == 1) {
            ++report.boundary_edges;
        } else if (sharing > 2) {
            ++report.non_manifold_edges;
        } else {
            const Side& first = sides[begin];
            const Side& second = sides[begin + 1];
            // Both sides start at the same corner: they run the same way.
            const bool same = triangles[first.face][first.k] == triangles[second.face][second.k];
            report.inconsistent_edges += same ? 1 : 0;
            const std::uint32_t flag = same ? kSameDirection : 0;
            neighbour[3 * first.face + first.k] = second.face | flag;
            neighbour[3 * second.face + second.k] = first.face | flag;
        }
        begin = end;
    }

    // Orientation: propagate a winding through each component and flip the side with fewer
    // triangles, so an authored winding survives when most of a component agrees with it.
    std::vector<std::uint32_t> component(triangle_count, kNone);
    std::vector<std::uint8_t> flip(triangle_count, 0);
    std::vector<std::uint32_t> component_seed;
    std::vector<std::uint8_t> component_orientable, component_invert;
    std::vector<std::uint32_t> stack;
    for (std::size_t seed = 0; seed < triangle_count; ++seed) {
        if (repeated(triangles[seed]) || component[seed] != kNone) continue;
        const auto id = static_cast<std::uint32_t>(component_seed.size());
        std::size_t size = 0, flipped = 0;
        bool orientable = true;
        component[seed] = id;
        stack.push_back(static_cast<std::uint32_t>(seed));
        while (!stack.empty()) {
            const std::uint32_t f = stack.back();
            stack.pop_back();
            ++size;
            flipped += flip[f];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t link = neighbour[3 * f + k];
                if (link == kNone) continue;
                const std::uint32_t g = link & ~kSameDirection;
                const std::uint8_t wanted = flip[f] ^ ((link & kSameDirection) ? 1 : 0);
                if (component[g] == kNone) {
                    component[g] = id;
                    flip[g] = wanted;
                    stack.push_back(g);
                } else if (flip[g] != wanted) {
                    orientable = false;
                }
            }
        }
        component_seed.push_back(static_cast<std::uint32_t>(seed));
        component_orientable.push_back(orientable);
        component_invert.push_back(2 * flipped > size);
        report.orientable = report.orientable && orientable;
    }
    const std::size_t component_count = component_seed.size();
    report.components = component_count;
    // From here on, flip[f] says whether triangle f has been turned over.
    for (std::size_t f = 0; f < triangle_count; ++f) {
        const std::uint32_t c = component[f];
        flip[f] = c != kNone && component_orientable[c] && flip[f] != component_invert[c];
        if (flip[f]) turn_over(f);
    }
    report.is_closed =
        report.boundary_edges == 0 && report.non_manifold_edges == 0 && report.orientable;

    if (report.is_closed) {
        // Outward: a shell nested inside an even number of others bounds the solid from
        // outside and must enclose positive volume; inside an odd number it bounds a cavity.
        std::vector<double> volume(component_count, 0.0);
        for (std::size_t f = 0; f < triangle_count; ++f) {
            if (component[f] == kNone) continue;
            const Eigen::Vector3d& reference = vertices[triangles[component_seed[component[f]]][0]];
            const Triangle& t = triangles[f];
            volume[component[f]] +=
                volume6(reference, vertices[t[0]], vertices[t[1]], vertices[t[2]]) / 6.0;
        }
        std::vector<std::uint8_t> outward_negative(component_count, 0);
        constexpr double kNestingBudget = 2e8;  // triangle tests
        if (component_count == 1) {
            outward_negative[0] = volume[0] < 0.0;
        } else if (double(component_count) * double(triangle_count) <= kNestingBudget) {
            // A direction unlikely to run along an edge of a modelled mesh.
            const Eigen::Vector3d direction = Eigen::Vector3d(0.5773, 0.6391, 0.5082).normalized();
            std::vector<std::uint8_t> parity(component_count);
            for (std::size_t c = 0; c < component_count; ++c) {
                std::fill(parity.begin(), parity.end(), 0);
                const Eigen::Vector3d& origin = vertices[triangles[component_seed[c]][0]];
                for (std::size_t f = 0; f < triangle_count; ++f) {
                    const std::uint32_t other = component[f];
                    if (other == kNone || other == c) continue;
                    const Triangle& t = triangles[f];
                    if (ray_crosses(origin, direction, vertices[t[0]], vertices[t[1]],
                                    vertices[t[2]])) {
                        parity[other] ^= 1;
                    }
                }
                const auto depth = std::count(parity.begin(), parity.end(), 1);
                outward_negative[c] = (volume[c] < 0.0) == (depth % 2 == 0);
            }
        } else {
            // Too many shells to nest cheaply: turn the mesh over only if it encloses a
            // negative volume in total.
            double total = 0.0;
            for (double v : volume) total += v;
            std::fill(outward_negative.begin(), outward_negative.end(), total < 0.0);
        }
        for (std::size_t f = 0; f < triangle_count; ++f) {
            if (component[f] == kNone || !outward_negative[component[f]]) continue;
            turn_over(f);
            flip[f] ^= 1;
        }
        for (std::size_t c = 0; c < component_count; ++c) {
            report.inverted_components += outward_negative[c];
            report.volume += outward_negative[c] ? -volume[c] : volume[c];
        }
    }

    report.flipped_triangles = static_cast<std::size_t>(std::count(flip.begin(), flip.end(), 1));

    // Drop zero-area triangles (exactly: the corner cross product is the zero vector).
    std::size_t kept = 0;
    for (std::size_t f = 0; f < triangle_count; ++f) {
        const Triangle& t = triangles[f];
        const Eigen::Vector3d area =
            (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
        if (repeated(t) || area.squaredNorm() == 0.0) continue;
        if (!corner_normals.empty()) corner_normals[kept] = corner_normals[f];
        triangles[kept++] = t;
    }
    if (!corner_normals.empty()) corner_normals.resize(kept);
    report.degenerate_triangles = triangle_count - kept;
    triangles.resize(kept);
    triangles.shrink_to_fit();
    report.triangles = kept;
    report.file_normals = !corner_normals.empty();
    require(kept > 0, kWhat, "count of triangles with non-zero area", "> 0", kept);

    // Angle-weighted vertex normals: each triangle adds its unit normal times its angle at the
    // vertex, so the result does not depend on how the surface around it is triangulated.
    auto& normals = mesh.normals;
    normals.assign(vertex_count, Eigen::Vector3d::Zero());
    for (const Triangle& t : triangles) {
        const Eigen::Vector3d face_normal =
            (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).normalized();
        for (int k = 0; k < 3; ++k) {
            const Eigen::Vector3d to_next = vertices[t[(k + 1) % 3]] - vertices[t[k]];
            const Eigen::Vector3d to_previous = vertices[t[(k + 2) % 3]] - vertices[t[k]];
            const double angle =
                std::atan2(to_next.cross(to_previous).norm(), to_next.dot(to_previous));
            normals[t[k]] += angle * face_normal;
        }
    }
    std::vector<std::uint8_t> referenced(vertex_count, 0);
    for (const Triangle& t : triangles) referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
    report.unreferenced_vertices =
        static_cast<std::size_t>(std::count(referenced.begin(), referenced.end(), 0));
    // A normal can also cancel out (a vertex shared by two opposite-facing sheets); it stays zero.
    for (Eigen::Vector3d& normal : normals) {
        const double length = normal.norm();
        if (length > 0.0) normal /= length;
    }
    return report;
}

MeshReport validate_mesh(TriangleMeshData& mesh, const MeshReport& as_read) {
    MeshReport report = validate_mesh(mesh);
    report.format = as_read.format;
    report.binary = as_read.binary;
    report.faces = as_read.faces;
    report.dropped_faces = as_read.dropped_faces;
    report.triangulated_faces = as_read.triangulated_faces;
    report.non_simple_faces = as_read.non_simple_faces;
    return report;
}

}  // namespace csgrt
