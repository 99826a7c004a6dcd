#pragma once

// What the flat shapes (plane, disk, annulus, rectangle, triangle) share: the frame of their
// normal and where a hit on their plane lies. Private to core/src.

#include <algorithm>

#include "csgrt/core/error.h"
#include "csgrt/core/hit.h"
#include "csgrt/core/surface_frame.h"

namespace csgrt::detail {

/// The frame of `normal` made unit length, for the constructor of the flat shape `shape`:
/// throws InvalidParameter naming its "normal" when that is not finite or is zero.
inline SurfaceFrame frame_of_normal(const Normal3& normal, const char* shape) {
    require_finite(normal, shape, "normal");
    const Normal3 unit = normalized_or_zero(normal);
    require(unit.squaredNorm() > 0.0, shape, "normal", "non-zero", normal);
    return SurfaceFrame::around(unit);
}

/// Where the ray crosses the plane through `anchor` with unit normal `normal`, at some t in
/// [t_min, t_max], and that point's offset from the anchor, formed as (o - anchor) + t d, which
/// keeps it accurate when o and the anchor are large but close. False when there is none.
inline bool plane_offset(const Ray& ray, const Point3& anchor, const Normal3& normal, double& t,
                         Vector3& offset) {
    if (!plane_crossing(ray, anchor, normal, t) || !ray.in_range(t)) return false;
    offset = (ray.origin - anchor) + t * ray.direction;
    return true;
}

/// The point of a flat shape with unit normal `normal` that lies `offset` from `anchor` as
/// o + t d gave it: the component along the normal that rounding left is dropped from `offset`
/// (written back, for the caller's uv) and the point is anchor + offset.
inline Point3 onto_plane(const Point3& anchor, Vector3& offset, const Normal3& normal) {
    offset -= offset.dot(normal) * normal;
    return anchor + offset;
}

/// A point of a flat shape around `center` with frame `frame`, at t along the ray: (x, z) are
/// its frame coordinates, from the offset (o - c) + t d (accurate when o and c are large but
/// close), and `point` is center + x x_axis + z z_axis, without the component along the
/// normal that rounding left.
struct FramePoint {
    Point3 point;
    double x;
    double z;
};

inline FramePoint point_in_frame(const Ray& ray, double t, const Point3& center,
                                 const SurfaceFrame& frame) {
    const Vector3 local = frame.to_local((ray.origin - center) + t * ray.direction);
    return {center + local.x() * frame.x_axis + local.z() * frame.z_axis, local.x(), local.z()};
}

/// The uv a flat shape kept in its record (a triangle's barycentrics, a parallelogram's
/// (s, t)), clamped into [0, 1].
inline Vector2 record_uv(const HitRecord& record) {
    return Vector2(std::clamp(double(record.u), 0.0, 1.0), std::clamp(double(record.v), 0.0, 1.0));
}

}  // namespace csgrt::detail
