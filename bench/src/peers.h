#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "csgrt/reference/cgal_reference.h"
#include "csgrt/accel/triangle_set.h"
#include "tracer.h"

namespace csgrt::bench {

/// CGAL's AABB tree as a Tracer: `first_intersected_primitive` for the nearest hit (CGAL's own
/// nearest query, with inexact constructions) and exact `do_intersect` for occlusion.
std::unique_ptr<Tracer> make_cgal_tracer(const CgalReference& reference);

/// What building an Embree scene cost.
struct EmbreeBuild {
    double build_milliseconds = 0.0;
    /// Everything the device allocated for the scene (Embree's memory monitor), and the part
    /// of it that is the vertex and index buffers (the rest is the BVH with its leaf data).
    std::size_t bytes = 0;
    std::size_t buffer_bytes = 0;
};

/// Whether the benchmark was built with Embree 3 (find_package(embree 3) found it).
bool embree_available();
/// "Embree 3.13.5" or "not built with Embree".
std::string embree_version();

/// Embree 3 over the same triangles as `set` (its float corners, three vertices a triangle,
/// unshared, as the set stores them), default build quality (medium), with
/// RTC_SCENE_FLAG_ROBUST when `robust`; the device builds with `build_threads` threads.
/// Queries are rtcIntersect1 and rtcOccluded1, one ray at a time like the other tracers, or
/// with `packets` rtcIntersect8 and rtcOccluded8 on eight consecutive rays at a time (flagged
/// coherent: Embree's packet path, for camera rays).
/// Throws std::runtime_error when Embree is not available or reports an error.
std::unique_ptr<Tracer> make_embree_tracer(const TriangleSet<float>& set, bool robust,
                                           int build_threads, EmbreeBuild* build = nullptr,
                                           bool packets = false);

}  // namespace csgrt::bench
