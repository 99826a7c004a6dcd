#pragma once

#include "csgrt/core/hit.h"
#include "csgrt/core/math.h"

namespace csgrt {

/// How far `offset_ray_origin` moves a point, relative to the magnitude of its coordinates:
/// 2^-16, the 256 float ulps of Waechter and Binder's int_scale. Meshes keep their vertices in
/// float and round the ray origin to float in the triangle test, so a double-sized offset
/// would not clear them (tests/render/shadow_offset_test.cpp measures 2^-22 as enough for
/// float triangles and 2^-25 as too little); analytic shapes, whose hit points are good to a few
/// double ulps, need far less but lose nothing visible (a shadow starts 1.5e-5 * |p| later).
inline constexpr double kRayOffsetRelative = 0x1.0p-16;

/// Below this fraction of the scene's magnitude a point's coordinates no longer shrink the
/// offset: near the origin the rounding of a hit point is set by the other coordinates and the
/// shape's parameters, not by the point's own tiny coordinates (Waechter and Binder's
/// `origin()` threshold, made relative to the scene instead of a fixed 1/32).
inline constexpr double kRayOffsetSceneFraction = 0x1.0p-10;

/// The origin for a ray leaving surface point `p` on the side `normal` points to (unit length,
/// the geometric normal turned to that side), moved along the normal far enough that the ray
/// cannot hit the surface it leaves through rounding error. The distance is scaled to the
/// coordinates' magnitude, as in Waechter and Binder, "A Fast and Robust Method for Avoiding
/// Self-Intersection", Ray Tracing Gems, 2019, ch. 6:
///   kRayOffsetRelative * max(max_i |p_i|, kRayOffsetSceneFraction * scene_magnitude),
/// where `scene_magnitude` is the largest coordinate magnitude of the scene (its bounds and
/// camera). Unlike their per-coordinate integer-ulp steps, the move is along the normal as a
/// whole, so it does not depend on how the normal is oriented against the axes.
Point3 offset_ray_origin(const Point3& p, const Normal3& normal, double scene_magnitude);

/// The distance `offset_ray_origin` moves `p`.
double ray_offset_distance(const Point3& p, double scene_magnitude);

/// The origin for a secondary ray leaving `hit` on the side `side` points to (unit length, the
/// geometric normal turned to that side), sized by the precision of the shape that was hit
/// rather than by where the scene is: `p + (|n|_1 e) n` for the hit's point error `e`, each
/// coordinate then stepped one ulp further from the surface so that the sum's own rounding
/// cannot take it back (pbrt-v4's OffsetRayOrigin). A few double ulps of the coordinates for
/// analytic shapes and CSG, the float margin for float triangles, carried through instances
/// (Hit::point_error); the renderer uses this, so a scene moved by 10^6 shadows as at the origin.
Point3 spawn_ray_origin(const Hit& hit, const Normal3& side);

/// The distance `spawn_ray_origin` moves the hit point along `side` (before the ulp steps).
double spawn_offset_distance(const Hit& hit, const Normal3& side);

}  // namespace csgrt
