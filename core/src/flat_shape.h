#pragma once

// What the flat shapes (plane, disk, annulus, rectangle, triangle) share: the frame of their
// normal and the hit on their plane. Private to core/src.

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

/// The hit of a flat shape with unit normal `normal` at record.t, whose point lies `offset`
/// from `anchor` as o + t d gave it: the component along the normal that rounding left is
/// dropped from `offset` (written back, for the caller's uv) and the point is anchor + offset.
/// Everything but uv is filled in.
inline Hit flat_hit(const Ray& ray, const HitRecord& record, const Shape* shape,
                    const Point3& anchor, Vector3& offset, const Normal3& normal) {
    Hit hit;
    hit.t = record.t;
    offset -= offset.dot(normal) * normal;
    hit.point = anchor + offset;
    hit.geometric_normal = normal;
    hit.shading_normal = normal;
    hit.shape = shape;
    hit.primitive_id = record.primitive;
    hit.front_face = ray.direction.dot(normal) < 0.0;
    return hit;
}

}  // namespace csgrt::detail
