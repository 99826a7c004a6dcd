#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/closest_point.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/ray.h"
#include "csgrt/csg/scene.h"

namespace csgrt {

/// A read-only view of `count` three-vectors laid out in caller memory: component k of vector
/// i is at component[k][i * stride]. Array-of-structs xyz is stride 3 (Open3D's (N, 6) rays:
/// stride 6, directions starting 3 elements in); separate x, y, z arrays are stride 1.
template <class Real>
struct VectorArray {
    const Real* component[3] = {nullptr, nullptr, nullptr};
    std::ptrdiff_t stride = 3;
    std::size_t count = 0;

    Eigen::Vector3d operator[](std::size_t i) const {
        const auto at = static_cast<std::ptrdiff_t>(i) * stride;
        return {double(component[0][at]), double(component[1][at]), double(component[2][at])};
    }
};

/// xyz triples side by side (array of structs). Throws InvalidParameter naming `what` unless
/// the size is a multiple of 3.
template <class Real>
VectorArray<Real> interleaved_vectors(std::span<const Real> xyz, std::string_view what);
/// `count` vectors starting at `first`, `stride` elements apart, components adjacent (the
/// origins or directions inside an (N, 6) ray array).
template <class Real>
VectorArray<Real> strided_vectors(const Real* first, std::size_t count, std::ptrdiff_t stride);
/// Separate x, y and z arrays (struct of arrays). Throws InvalidParameter naming `what` unless
/// the three have one size.
template <class Real>
VectorArray<Real> separate_vectors(std::span<const Real> x, std::span<const Real> y,
                                   std::span<const Real> z, std::string_view what);

/// N rays: origins, directions (not renormalised, so t is in the caller's units) and the
/// interval [t_min, t_max] of each, per ray when the span is given, else the default for all.
template <class Real>
struct RayArrays {
    VectorArray<Real> origins;
    VectorArray<Real> directions;
    std::span<const Real> t_min;
    std::span<const Real> t_max;
    double default_t_min = 0.0;
    double default_t_max = kInfinity;

    std::size_t size() const { return origins.count; }
    /// Ray i as the single-ray queries take it (in double; float inputs convert exactly).
    Ray ray(std::size_t i) const {
        Ray r;
        r.origin = origins[i];
        r.direction = directions[i];
        r.t_min = t_min.empty() ? default_t_min : double(t_min[i]);
        r.t_max = t_max.empty() ? default_t_max : double(t_max[i]);
        return r;
    }
};

/// Where the nearest-hit batch writes its answers, one slot per ray (uv: 2 values a ray,
/// normals: 3). Each output is optional: an empty span is not computed, and a caller who asks
/// only for t pays only for the traversal (for a bare triangle structure; a Scene finishes
/// every hit, see docs/python.md). A miss writes t = +infinity, ids kNoIndex, uv and normals 0.
template <class Real>
struct NearestHitOutputs {
    std::span<Real> t;
    std::span<std::uint32_t> object_id;
    std::span<std::uint32_t> primitive_id;
    std::span<Real> uv;
    std::span<Real> geometric_normal;
    std::span<Real> shading_normal;
    /// A scene's only: the material index of the surface hit, the innermost painted
    /// operand's (csg/painted.h) or else its object's, as the renderer shades it; kNoIndex on
    /// a miss. A triangle structure has no materials: asking it throws InvalidParameter.
    std::span<std::uint32_t> material;
};

/// One crossing of a ray with a surface, as the crossing list reports it.
template <class Real>
struct CrossingOutputs {
    /// Per ray: where its crossings start in the arrays below, count + 1 entries (the last is
    /// the total), as `crossing_offsets` computes them from the counts.
    std::span<const std::uint64_t> offsets;
    std::span<Real> t;
    std::span<std::uint32_t> object_id;
    std::span<std::uint32_t> primitive_id;
    /// The hit's surface parameters (2 values a crossing): uv for a scene, the barycentrics of
    /// corners 1 and 2 for triangles.
    std::span<Real> uv;
    /// 1 where the ray enters the surface's solid side (direction against the outward
    /// geometric normal), 0 where it leaves. Optional.
    std::span<std::uint8_t> entering;
};

/// How a batch runs.
struct BatchConfig {
    /// Worker threads; 0 uses every core oneTBB sees. Answers do not depend on it.
    int threads = 0;
    /// Rays (or points) per task handed to a thread.
    std::size_t grain = 1024;
};

/// Several meshes' triangles in one set with one ray structure and, for point queries, one
/// closest-point tree: what Open3D's RaycastingScene holds. `object_of_triangle` (optional)
/// names the mesh of each triangle and `first_triangle` (one per mesh) where that mesh's
/// triangles start, so ids come out as (mesh, triangle within the mesh); without them every
/// triangle belongs to object 0 and keeps its set index. The pointers must outlive the queries.
template <class Real>
struct TriangleStructure {
    const TriangleSet<Real>* triangles = nullptr;
    const Accelerator<TriangleSet<Real>>* structure = nullptr;
    /// Needed only by the point queries (closest point, distance).
    const ClosestPointTree<Real>* closest_points = nullptr;
    std::span<const std::uint32_t> object_of_triangle;
    std::span<const std::uint32_t> first_triangle;
};

/// The batch queries. Every function runs ray i's (or point i's) single query, writes slot i,
/// and nothing else: inputs are read once, outputs are caller-owned and sized by the caller
/// (InvalidParameter, naming the output, for a span of the wrong size), nothing is allocated
/// per ray, and the answers are bit-identical for every thread count and to the single-ray
/// queries (Scene::intersect, Accelerator::intersect, ...). An invalid ray (is_valid) gets a
/// miss in its slot; a non-finite point is outside, at infinite distance.
///
/// Nearest hit per ray over a committed scene (InvalidParameter if it is not committed).
template <class Real>
void intersect(const Scene& scene, const RayArrays<Real>& rays,
               const NearestHitOutputs<Real>& outputs, const BatchConfig& config = {});
template <class Real, class SetReal>
void intersect(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
               const NearestHitOutputs<Real>& outputs, const BatchConfig& config = {});

/// Whether anything is hit in each ray's interval (1) or not (0).
template <class Real>
void occluded(const Scene& scene, const RayArrays<Real>& rays, std::span<std::uint8_t> occluded,
              const BatchConfig& config = {});
template <class Real, class SetReal>
void occluded(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
              std::span<std::uint8_t> occluded, const BatchConfig& config = {});

/// How many surface crossings each ray makes in its interval. A scene's crossings are its
/// successive nearest hits (each next one searched strictly beyond the last t); a triangle
/// structure's are its triangle hits, with hits at one t on one mesh (a ray through a shared
/// edge or vertex) counted once.
template <class Real>
void count_crossings(const Scene& scene, const RayArrays<Real>& rays,
                     std::span<std::uint32_t> counts, const BatchConfig& config = {});
template <class Real, class SetReal>
void count_crossings(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
                     std::span<std::uint32_t> counts, const BatchConfig& config = {});

/// Exclusive prefix sums of `counts` into `offsets` (counts.size() + 1 entries).
void crossing_offsets(std::span<const std::uint32_t> counts, std::span<std::uint64_t> offsets);

/// Every crossing of each ray, sorted by t, into the slots `outputs.offsets` gives it (from
/// count_crossings and crossing_offsets; a ray that finds a different count than its slot
/// holds, which cannot happen for the same inputs, throws InvalidParameter).
template <class Real>
void list_crossings(const Scene& scene, const RayArrays<Real>& rays,
                    const CrossingOutputs<Real>& outputs, const BatchConfig& config = {});
template <class Real, class SetReal>
void list_crossings(const TriangleStructure<SetReal>& mesh, const RayArrays<Real>& rays,
                    const CrossingOutputs<Real>& outputs, const BatchConfig& config = {});

/// Point membership: 1 where point i is inside a solid object of the scene (Shape::contains:
/// CSG trees, closed meshes, analytic solids), 0 elsewhere.
template <class Real>
void contains(const Scene& scene, const VectorArray<Real>& points, std::span<std::uint8_t> inside,
              const BatchConfig& config = {});
/// For closed triangle meshes: 1 where the ray from point i along a fixed direction crosses the
/// surface an odd number of times (crossings counted as count_crossings counts them), as
/// Open3D's compute_occupancy decides it. Orientation does not matter.
template <class Real, class SetReal>
void contains(const TriangleStructure<SetReal>& mesh, const VectorArray<Real>& points,
              std::span<std::uint8_t> inside, const BatchConfig& config = {});

/// Where the point queries write, one slot per point (points: 3 values, uv: 2). Optional each.
template <class Real>
struct ClosestPointOutputs {
    std::span<Real> point;
    std::span<std::uint32_t> object_id;
    std::span<std::uint32_t> primitive_id;
    std::span<Real> uv;
    /// The unit geometric normal of the nearest triangle.
    std::span<Real> normal;
    /// Unsigned distance.
    std::span<Real> distance;
    /// Distance, negative inside (as `contains` decides inside).
    std::span<Real> signed_distance;
};

/// Nearest surface point of each point (the structure's ClosestPointTree, which must be set).
template <class Real, class SetReal>
void closest_points(const TriangleStructure<SetReal>& mesh, const VectorArray<Real>& points,
                    const ClosestPointOutputs<Real>& outputs, const BatchConfig& config = {});

/// The unit geometric normal of triangle i of `set` (its winding's right-hand normal; zero for
/// a degenerate triangle).
template <class Real>
Normal3 triangle_normal(const TriangleSet<Real>& set, std::size_t i);

}  // namespace csgrt
