#include "csgrt/csg/batch.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <string>

#include "csgrt/core/error.h"
#include "ray_packet.h"

namespace csgrt {

namespace {

/// A ray from a point for the parity test of `contains`: no axis-aligned or diagonal component
/// ratios, so it is unlikely to run along the edges and faces of meshes built on a grid.
const Vector3 kParityDirection = Vector3(0.2718281828, 0.5772156649, 0.7701988129).normalized();

void check_size(std::size_t size, std::size_t expected, std::string_view what) {
    if (size != expected) {
        throw InvalidParameter(std::string(what) + ": expected " + std::to_string(expected) +
                               " values, got " + std::to_string(size));
    }
}
void check_optional(std::size_t size, std::size_t expected, std::string_view what) {
    if (size != 0) check_size(size, expected, what);
}

template <class Real>
void check_rays(const RayArrays<Real>& rays) {
    const std::size_t n = rays.size();
    check_size(rays.directions.count, n, "directions");
    check_optional(rays.t_min.size(), n, "t_min");
    check_optional(rays.t_max.size(), n, "t_max");
}

/// Runs body(begin, end, scratch) over [0, count) in blocks of `grain`, on config.threads
/// threads, each thread with its own scratch. Every index is handled by exactly one call and
/// what a call writes depends only on its indices, so the answers are the same for any
/// thread count and any split.
template <class Body>
void for_blocks(std::size_t count, const BatchConfig& config, const Body& body) {
    if (count == 0) return;
    if (config.threads < 0) {
        throw InvalidParameter("threads: expected 0 (every core) or a positive count, got " +
                               std::to_string(config.threads));
    }
    const std::size_t grain = std::max<std::size_t>(1, config.grain);
    if (config.threads == 1 || count <= grain) {
        QueryScratch scratch;
        body(std::size_t{0}, count, scratch);
        return;
    }
    tbb::enumerable_thread_specific<QueryScratch> scratches;
    tbb::task_arena arena(config.threads > 0 ? config.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, grain),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              body(range.begin(), range.end(), scratches.local());
                          });
    });
}

/// Runs body(i, ray i, scratch) for every ray, in blocks as for_blocks runs them: the walk
/// of every batch query that answers ray by ray (after check_rays).
template <class Real, class Body>
void for_each_ray(const RayArrays<Real>& rays, const BatchConfig& config, const Body& body) {
    for_blocks(rays.size(), config, [&](std::size_t begin, std::size_t end, QueryScratch& s) {
        for (std::size_t i = begin; i < end; ++i) body(i, rays.ray(i), s);
    });
}

template <class Real>
void write3(std::span<Real> out, std::size_t i, const Vector3& v) {
    if (out.empty()) return;
    out[3 * i] = static_cast<Real>(v.x());
    out[3 * i + 1] = static_cast<Real>(v.y());
    out[3 * i + 2] = static_cast<Real>(v.z());
}
template <class Real>
void write2(std::span<Real> out, std::size_t i, double u, double v) {
    if (out.empty()) return;
    out[2 * i] = static_cast<Real>(u);
    out[2 * i + 1] = static_cast<Real>(v);
}
template <class T>
void write1(std::span<T> out, std::size_t i, T value) {
    if (!out.empty()) out[i] = value;
}

template <class Real>
void check_outputs(const NearestHitOutputs<Real>& outputs, std::size_t n) {
    check_optional(outputs.t.size(), n, "t");
    check_optional(outputs.object_id.size(), n, "object_id");
    check_optional(outputs.primitive_id.size(), n, "primitive_id");
    check_optional(outputs.uv.size(), 2 * n, "uv");
    check_optional(outputs.geometric_normal.size(), 3 * n, "geometric_normal");
    check_optional(outputs.shading_normal.size(), 3 * n, "shading_normal");
    check_optional(outputs.material.size(), n, "material");
}

template <class Real>
void write_miss(const NearestHitOutputs<Real>& outputs, std::size_t i) {
    write1(outputs.t, i, static_cast<Real>(kInfinity));
    write1(outputs.object_id, i, kNoIndex);
    write1(outputs.primitive_id, i, kNoIndex);
    write2(outputs.uv, i, 0.0, 0.0);
    write3(outputs.geometric_normal, i, Vector3::Zero());
    write3(outputs.shading_normal, i, Vector3::Zero());
    write1(outputs.material, i, kNoIndex);
}

void check_committed(const Scene& scene) {
    if (!scene.is_committed()) {
        throw InvalidParameter("scene: not committed (call commit() before batch queries)");
    }
}

/// Object and per-object triangle index of triangle i of a (possibly multi-mesh) structure.
template <class Real>
void triangle_ids(const TriangleStructure<Real>& mesh, std::uint32_t i, std::uint32_t& object,
                  std::uint32_t& primitive) {
    if (mesh.object_of_triangle.empty()) {
        object = 0;
        primitive = i;
        return;
    }
    object = mesh.object_of_triangle[i];
    primitive = i - mesh.first_triangle[object];
}

template <class Real>
void check_structure(const TriangleStructure<Real>& mesh) {
    if (mesh.triangles == nullptr || mesh.structure == nullptr) {
        throw InvalidParameter("mesh: the triangle set and its structure must both be given");
    }
    check_optional(mesh.object_of_triangle.size(), mesh.triangles->size(), "object_of_triangle");
    if (!mesh.object_of_triangle.empty() && mesh.first_triangle.empty()) {
        throw InvalidParameter("first_triangle: needed with object_of_triangle");
    }
}

/// The preconditions of every ray query, checked before any ray is traced: a committed scene
/// (or a complete triangle structure) and ray arrays of one size.
template <class Real>
void check_inputs(const Scene& scene, const RayArrays<Real>& rays) {
    check_committed(scene);
    check_rays(rays);
}
template <class Real, class SetReal>
void check_inputs(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays) {
    check_structure(mesh);
    check_rays(rays);
}

/// A scene's crossings along `ray`: its successive nearest hits, each searched strictly beyond
/// the last. `visit(hit)` sees each; returns the count.
template <class Visit>
std::uint32_t scene_crossings(const Scene& scene, Ray ray, QueryScratch& scratch,
                              const Visit& visit) {
    std::uint32_t count = 0;
    while (auto hit = scene.intersect(ray, scratch)) {
        ++count;
        visit(*hit);
        if (!(hit->t < ray.t_max)) break;
        ray.t_min = next_up(hit->t);
    }
    return count;
}

/// A triangle structure's crossings along `ray`, sorted by (t, triangle), with later hits at
/// the same t on the same object (shared edges and vertices) dropped. Borrowed from scratch.
template <class Real>
std::size_t triangle_crossings(const TriangleStructure<Real>& mesh, const Ray& ray,
                               std::vector<HitRecord>& hits, QueryScratch& scratch) {
    if (!is_valid(ray)) return 0;
    mesh.structure->all_hits(ray, hits, scratch);
    std::sort(hits.begin(), hits.end(), [](const HitRecord& a, const HitRecord& b) {
        return a.t < b.t || (a.t == b.t && a.primitive < b.primitive);
    });
    std::size_t kept = 0;
    std::uint32_t last_object = kNoIndex;
    for (std::size_t k = 0; k < hits.size(); ++k) {
        std::uint32_t object, primitive;
        triangle_ids(mesh, hits[k].primitive, object, primitive);
        if (kept > 0 && hits[k].t == hits[kept - 1].t && object == last_object) continue;
        hits[kept++] = hits[k];
        last_object = object;
    }
    hits.resize(kept);
    return kept;
}

template <class Real>
void check_crossing_outputs(const CrossingOutputs<Real>& outputs, std::size_t n) {
    check_size(outputs.offsets.size(), n + 1, "offsets");
    const std::uint64_t total = outputs.offsets[n];
    check_optional(outputs.t.size(), total, "t");
    check_optional(outputs.object_id.size(), total, "object_id");
    check_optional(outputs.primitive_id.size(), total, "primitive_id");
    check_optional(outputs.uv.size(), 2 * total, "uv");
    check_optional(outputs.entering.size(), total, "entering");
}

void check_slot(std::uint64_t found, std::uint64_t slot, std::size_t ray) {
    if (found != slot) {
        throw InvalidParameter("offsets: ray " + std::to_string(ray) + " has " +
                               std::to_string(found) + " crossings but its slot holds " +
                               std::to_string(slot) +
                               " (offsets must come from count_crossings on the same rays)");
    }
}

template <class Real>
bool triangle_contains(const TriangleStructure<Real>& mesh, const Point3& p,
                       std::vector<HitRecord>& hits, QueryScratch& scratch) {
    if (!is_finite(p)) return false;
    Ray ray;
    ray.origin = p;
    ray.direction = kParityDirection;
    return triangle_crossings(mesh, ray, hits, scratch) % 2 == 1;
}

}  // namespace

template <class Real>
VectorArray<Real> interleaved_vectors(std::span<const Real> xyz, std::string_view what) {
    if (xyz.size() % 3 != 0) {
        throw InvalidParameter(std::string(what) + ": expected 3 values per vector, got " +
                               std::to_string(xyz.size()) + " values");
    }
    return strided_vectors(xyz.data(), xyz.size() / 3, 3);
}

template <class Real>
VectorArray<Real> strided_vectors(const Real* first, std::size_t count, std::ptrdiff_t stride) {
    VectorArray<Real> vectors;
    vectors.component[0] = first;
    vectors.component[1] = first + 1;
    vectors.component[2] = first + 2;
    vectors.stride = stride;
    vectors.count = count;
    return vectors;
}

template <class Real>
VectorArray<Real> separate_vectors(std::span<const Real> x, std::span<const Real> y,
                                   std::span<const Real> z, std::string_view what) {
    if (y.size() != x.size() || z.size() != x.size()) {
        throw InvalidParameter(std::string(what) + ": x, y and z must have one size, got " +
                               std::to_string(x.size()) + ", " + std::to_string(y.size()) +
                               " and " + std::to_string(z.size()));
    }
    VectorArray<Real> vectors;
    vectors.component[0] = x.data();
    vectors.component[1] = y.data();
    vectors.component[2] = z.data();
    vectors.stride = 1;
    vectors.count = x.size();
    return vectors;
}

template <class Real>
Normal3 triangle_normal(const TriangleSet<Real>& set, std::size_t i) {
    const Vector3 a = set.corner(i, 0).template cast<double>();
    const Vector3 b = set.corner(i, 1).template cast<double>();
    const Vector3 c = set.corner(i, 2).template cast<double>();
    const Vector3 n = (b - a).cross(c - a);
    const double length = n.norm();
    return length > 0.0 ? Normal3(n / length) : Normal3::Zero();
}

template <class Real>
void intersect(const Scene& scene, const RayArrays<Real>& rays,
               const NearestHitOutputs<Real>& outputs, const BatchConfig& config) {
    check_inputs(scene, rays);
    check_outputs(outputs, rays.size());
    for_each_ray(rays, config, [&](std::size_t i, const Ray& ray, QueryScratch& s) {
        const auto hit = scene.intersect(ray, s);
        if (!hit) {
            write_miss(outputs, i);
            return;
        }
        write1(outputs.t, i, static_cast<Real>(hit->t));
        write1(outputs.object_id, i, hit->object_id);
        write1(outputs.primitive_id, i, hit->primitive_id);
        write2(outputs.uv, i, hit->uv.x(), hit->uv.y());
        write3(outputs.geometric_normal, i, hit->geometric_normal);
        write3(outputs.shading_normal, i, hit->shading_normal);
        write1(outputs.material, i,
               hit->material != kNoIndex ? hit->material
                                         : scene.objects()[hit->object_id].material);
    });
}

template <class Real, class SetReal>
void intersect(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
               const NearestHitOutputs<Real>& outputs, const BatchConfig& config) {
    check_inputs(mesh, rays);
    check_outputs(outputs, rays.size());
    if (!outputs.material.empty()) {
        throw InvalidParameter("material: a triangle structure has no materials");
    }
    const bool wants_ids = !outputs.object_id.empty() || !outputs.primitive_id.empty();
    const bool wants_normal = !outputs.geometric_normal.empty() || !outputs.shading_normal.empty();
    const auto* bvh = dynamic_cast<const Bvh<TriangleSet<SetReal>>*>(mesh.structure);
    for_blocks(rays.size(), config, [&](std::size_t begin, std::size_t end, QueryScratch& s) {
        detail::RayGroup group;
        for (std::size_t i = begin; i < end; i += group.size) {
            group.load(rays, i, end);
            group.nearest(bvh, *mesh.structure, s);
            const std::size_t n = group.size;
            const HitRecord* records = group.records;
            const bool* hit = group.hit;
            if (!outputs.t.empty()) {
                for (std::size_t k = 0; k < n; ++k) {
                    outputs.t[i + k] = static_cast<Real>(hit[k] ? records[k].t : kInfinity);
                }
            }
            if (wants_ids) {
                for (std::size_t k = 0; k < n; ++k) {
                    std::uint32_t object = kNoIndex, primitive = kNoIndex;
                    if (hit[k]) triangle_ids(mesh, records[k].primitive, object, primitive);
                    write1(outputs.object_id, i + k, object);
                    write1(outputs.primitive_id, i + k, primitive);
                }
            }
            if (!outputs.uv.empty()) {
                for (std::size_t k = 0; k < n; ++k) {
                    write2(outputs.uv, i + k, hit[k] ? double(records[k].u) : 0.0,
                           hit[k] ? double(records[k].v) : 0.0);
                }
            }
            if (wants_normal) {
                for (std::size_t k = 0; k < n; ++k) {
                    // Bare triangles have no vertex normals: shading is the geometric normal.
                    const Normal3 normal = hit[k]
                                               ? triangle_normal(*mesh.triangles, records[k].primitive)
                                               : Normal3::Zero();
                    write3(outputs.geometric_normal, i + k, normal);
                    write3(outputs.shading_normal, i + k, normal);
                }
            }
        }
    });
}

template <class Real>
void occluded(const Scene& scene, const RayArrays<Real>& rays, std::span<std::uint8_t> occluded,
              const BatchConfig& config) {
    check_inputs(scene, rays);
    check_size(occluded.size(), rays.size(), "occluded");
    for_each_ray(rays, config, [&](std::size_t i, const Ray& ray, QueryScratch& s) {
        occluded[i] = scene.occluded(ray, s);
    });
}

template <class Real, class SetReal>
void occluded(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
              std::span<std::uint8_t> occluded, const BatchConfig& config) {
    check_inputs(mesh, rays);
    check_size(occluded.size(), rays.size(), "occluded");
    const auto* bvh = dynamic_cast<const Bvh<TriangleSet<SetReal>>*>(mesh.structure);
    for_blocks(rays.size(), config, [&](std::size_t begin, std::size_t end, QueryScratch& s) {
        detail::RayGroup group;
        for (std::size_t i = begin; i < end; i += group.size) {
            group.load(rays, i, end);
            group.occluded(bvh, *mesh.structure, s);
            for (std::size_t k = 0; k < group.size; ++k) occluded[i + k] = group.hit[k];
        }
    });
}

template <class Real>
void count_crossings(const Scene& scene, const RayArrays<Real>& rays,
                     std::span<std::uint32_t> counts, const BatchConfig& config) {
    check_inputs(scene, rays);
    check_size(counts.size(), rays.size(), "counts");
    for_each_ray(rays, config, [&](std::size_t i, const Ray& ray, QueryScratch& s) {
        counts[i] = scene_crossings(scene, ray, s, [](const Hit&) {});
    });
}

template <class Real, class SetReal>
void count_crossings(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
                     std::span<std::uint32_t> counts, const BatchConfig& config) {
    check_inputs(mesh, rays);
    check_size(counts.size(), rays.size(), "counts");
    for_each_ray(rays, config, [&](std::size_t i, const Ray& ray, QueryScratch& s) {
        BorrowedHits hits(s);
        counts[i] = static_cast<std::uint32_t>(triangle_crossings(mesh, ray, hits.list(), s));
    });
}

void crossing_offsets(std::span<const std::uint32_t> counts, std::span<std::uint64_t> offsets) {
    check_size(offsets.size(), counts.size() + 1, "offsets");
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        offsets[i] = total;
        total += counts[i];
    }
    offsets[counts.size()] = total;
}

template <class Real>
void list_crossings(const Scene& scene, const RayArrays<Real>& rays,
                    const CrossingOutputs<Real>& outputs, const BatchConfig& config) {
    check_inputs(scene, rays);
    check_crossing_outputs(outputs, rays.size());
    for_each_ray(rays, config, [&](std::size_t i, const Ray& ray, QueryScratch& s) {
        const std::uint64_t first = outputs.offsets[i];
        const std::uint64_t slot = outputs.offsets[i + 1] - first;
        std::uint64_t k = 0;
        const std::uint32_t found = scene_crossings(scene, ray, s, [&](const Hit& hit) {
            if (k < slot) {
                const std::size_t at = first + k;
                write1(outputs.t, at, static_cast<Real>(hit.t));
                write1(outputs.object_id, at, hit.object_id);
                write1(outputs.primitive_id, at, hit.primitive_id);
                write2(outputs.uv, at, hit.uv.x(), hit.uv.y());
                write1(outputs.entering, at, std::uint8_t(hit.front_face ? 1 : 0));
            }
            ++k;
        });
        check_slot(found, slot, i);
    });
}

template <class Real, class SetReal>
void list_crossings(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
                    const CrossingOutputs<Real>& outputs, const BatchConfig& config) {
    check_inputs(mesh, rays);
    check_crossing_outputs(outputs, rays.size());
    for_each_ray(rays, config, [&](std::size_t i, const Ray& ray, QueryScratch& s) {
        BorrowedHits borrowed(s);
        std::vector<HitRecord>& hits = borrowed.list();
        const std::size_t found = triangle_crossings(mesh, ray, hits, s);
        const std::uint64_t first = outputs.offsets[i];
        check_slot(found, outputs.offsets[i + 1] - first, i);
        for (std::size_t k = 0; k < found; ++k) {
            const std::size_t at = first + k;
            std::uint32_t object, primitive;
            triangle_ids(mesh, hits[k].primitive, object, primitive);
            write1(outputs.t, at, static_cast<Real>(hits[k].t));
            write1(outputs.object_id, at, object);
            write1(outputs.primitive_id, at, primitive);
            write2(outputs.uv, at, double(hits[k].u), double(hits[k].v));
            if (!outputs.entering.empty()) {
                const Normal3 n = triangle_normal(*mesh.triangles, hits[k].primitive);
                outputs.entering[at] = n.dot(ray.direction) < 0.0 ? 1 : 0;
            }
        }
    });
}

template <class Real>
void contains(const Scene& scene, const VectorArray<Real>& points, std::span<std::uint8_t> inside,
              const BatchConfig& config) {
    check_committed(scene);
    check_size(inside.size(), points.count, "inside");
    const auto& objects = scene.objects();
    for_blocks(points.count, config, [&](std::size_t begin, std::size_t end, QueryScratch&) {
        for (std::size_t i = begin; i < end; ++i) {
            const Point3 p = points[i];
            bool in = false;
            if (is_finite(p)) {
                for (const SceneObject& object : objects) {
                    if (object.shape->is_solid() && object.shape->bounds().contains(p) &&
                        object.shape->contains(p)) {
                        in = true;
                        break;
                    }
                }
            }
            inside[i] = in ? 1 : 0;
        }
    });
}

template <class Real, class SetReal>
void contains(const TriangleStructure<SetReal>& mesh, const VectorArray<Real>& points,
              std::span<std::uint8_t> inside, const BatchConfig& config) {
    check_structure(mesh);
    check_size(inside.size(), points.count, "inside");
    for_blocks(points.count, config, [&](std::size_t begin, std::size_t end, QueryScratch& s) {
        for (std::size_t i = begin; i < end; ++i) {
            BorrowedHits hits(s);
            inside[i] = triangle_contains(mesh, points[i], hits.list(), s) ? 1 : 0;
        }
    });
}

template <class Real, class SetReal>
void closest_points(const TriangleStructure<SetReal>& mesh, const VectorArray<Real>& points,
                    const ClosestPointOutputs<Real>& outputs, const BatchConfig& config) {
    check_structure(mesh);
    if (mesh.closest_points == nullptr) {
        throw InvalidParameter("mesh: closest_points (a ClosestPointTree) is needed");
    }
    const std::size_t n = points.count;
    check_optional(outputs.point.size(), 3 * n, "point");
    check_optional(outputs.object_id.size(), n, "object_id");
    check_optional(outputs.primitive_id.size(), n, "primitive_id");
    check_optional(outputs.uv.size(), 2 * n, "uv");
    check_optional(outputs.normal.size(), 3 * n, "normal");
    check_optional(outputs.distance.size(), n, "distance");
    check_optional(outputs.signed_distance.size(), n, "signed_distance");
    for_blocks(n, config, [&](std::size_t begin, std::size_t end, QueryScratch& s) {
        for (std::size_t i = begin; i < end; ++i) {
            const Point3 p = points[i];
            const ClosestPoint nearest = mesh.closest_points->closest(p);
            const double distance = std::sqrt(nearest.squared_distance);
            write3(outputs.point, i, nearest.point);
            write1(outputs.distance, i, static_cast<Real>(distance));
            if (nearest.primitive == kNoIndex) {
                write1(outputs.object_id, i, kNoIndex);
                write1(outputs.primitive_id, i, kNoIndex);
                write2(outputs.uv, i, 0.0, 0.0);
                write3(outputs.normal, i, Vector3::Zero());
                write1(outputs.signed_distance, i, static_cast<Real>(kInfinity));
                continue;
            }
            std::uint32_t object, primitive;
            triangle_ids(mesh, nearest.primitive, object, primitive);
            write1(outputs.object_id, i, object);
            write1(outputs.primitive_id, i, primitive);
            write2(outputs.uv, i, nearest.u, nearest.v);
            write3(outputs.normal, i, triangle_normal(*mesh.triangles, nearest.primitive));
            if (!outputs.signed_distance.empty()) {
                BorrowedHits hits(s);
                const bool in = triangle_contains(mesh, p, hits.list(), s);
                outputs.signed_distance[i] = static_cast<Real>(in ? -distance : distance);
            }
        }
    });
}

// Every query for float and double inputs, and the triangle queries for either precision of
// rays over either precision of triangles.
#define CSGRT_BATCH_SCENE(Real)                                                                   \
    template VectorArray<Real> interleaved_vectors(std::span<const Real>, std::string_view);      \
    template VectorArray<Real> strided_vectors(const Real*, std::size_t, std::ptrdiff_t);         \
    template VectorArray<Real> separate_vectors(std::span<const Real>, std::span<const Real>,     \
                                                std::span<const Real>, std::string_view);         \
    template Normal3 triangle_normal(const TriangleSet<Real>&, std::size_t);                      \
    template void intersect(const Scene&, const RayArrays<Real>&, const NearestHitOutputs<Real>&, \
                            const BatchConfig&);                                                  \
    template void occluded(const Scene&, const RayArrays<Real>&, std::span<std::uint8_t>,         \
                           const BatchConfig&);                                                   \
    template void count_crossings(const Scene&, const RayArrays<Real>&, std::span<std::uint32_t>, \
                                  const BatchConfig&);                                            \
    template void list_crossings(const Scene&, const RayArrays<Real>&,                            \
                                 const CrossingOutputs<Real>&, const BatchConfig&);               \
    template void contains(const Scene&, const VectorArray<Real>&, std::span<std::uint8_t>,       \
                           const BatchConfig&);
#define CSGRT_BATCH_TRIANGLES(Real, SetReal)                                                  \
    template void intersect(const TriangleStructure<SetReal>&, const RayArrays<Real>&,        \
                            const NearestHitOutputs<Real>&, const BatchConfig&);              \
    template void occluded(const TriangleStructure<SetReal>&, const RayArrays<Real>&,         \
                           std::span<std::uint8_t>, const BatchConfig&);                      \
    template void count_crossings(const TriangleStructure<SetReal>&, const RayArrays<Real>&,  \
                                  std::span<std::uint32_t>, const BatchConfig&);              \
    template void list_crossings(const TriangleStructure<SetReal>&, const RayArrays<Real>&,   \
                                 const CrossingOutputs<Real>&, const BatchConfig&);           \
    template void contains(const TriangleStructure<SetReal>&, const VectorArray<Real>&,       \
                           std::span<std::uint8_t>, const BatchConfig&);                      \
    template void closest_points(const TriangleStructure<SetReal>&, const VectorArray<Real>&, \
                                 const ClosestPointOutputs<Real>&, const BatchConfig&);

CSGRT_BATCH_SCENE(float)
CSGRT_BATCH_SCENE(double)
CSGRT_BATCH_TRIANGLES(float, float)
CSGRT_BATCH_TRIANGLES(float, double)
CSGRT_BATCH_TRIANGLES(double, float)
CSGRT_BATCH_TRIANGLES(double, double)
#undef CSGRT_BATCH_SCENE
#undef CSGRT_BATCH_TRIANGLES

}  // namespace csgrt
