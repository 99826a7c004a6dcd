#pragma once

// What the bounded solids of revolution (cylinder, cone) do with their line interval once
// they have it: the nearest crossing and the span; and where a hit on their caps or on a
// cylinder's side (also a part cylinder's) lies. Private to core/src.

#include <algorithm>
#include <cmath>
#include <optional>

#include "csgrt/core/angle_range.h"
#include "csgrt/core/leaf_shape.h"
#include "csgrt/core/line_interval.h"
#include "csgrt/core/span.h"

namespace csgrt::detail {

/// The first finite end of `span` in [t_min, t_max] (the entry, else the exit): a bounded
/// solid's nearest crossing.
inline std::optional<Crossing> first_crossing(const LineInterval& span, const Ray& ray) {
    if (span.empty()) return {};
    if (ray.in_range(span.t0) && std::isfinite(span.t0)) {
        return Crossing{.t = span.t0, .primitive = span.surface0};
    }
    if (ray.in_range(span.t1) && std::isfinite(span.t1)) {
        return Crossing{.t = span.t1, .primitive = span.surface1};
    }
    return {};
}

/// Appends `span` to `spans` as `shape`'s span when it meets [t_min, t_max] and both ends are
/// finite: a bounded solid's ends are, but for underflowed directions, which cross nothing.
inline void push_span(const LineInterval& span, const Ray& ray, const Shape* shape,
                      SpanList& spans) {
    if (span.empty() || span.t1 < ray.t_min || span.t0 > ray.t_max || !std::isfinite(span.t0) ||
        !std::isfinite(span.t1)) {
        return;
    }
    spans.push_back(Span{HitRecord{.t = span.t0, .shape = shape, .primitive = span.surface0},
                         HitRecord{.t = span.t1, .shape = shape, .primitive = span.surface1}});
}

/// A hit on the cap y = `height` of a solid of revolution about the y axis (`top`: normal +y,
/// else -y) whose rim has `radius`; `p` is o + t d and `distance` its distance from the axis.
/// The point is put exactly on the cap's plane; uv = (phi / 2 pi, distance / radius).
inline SurfacePoint cap_point(Point3 p, double distance, double height, bool top, double radius) {
    p.y() = height;
    return {p, Normal3(0.0, top ? 1.0 : -1.0, 0.0),
            Vector2(AngleRange::azimuth(p.x(), p.z()) / kTwoPi, std::min(distance / radius, 1.0))};
}

/// Moves `p` (o + t d, at `distance` from the y axis) radially onto the side of the cylinder
/// of `radius` about that axis, which removes the rounding of o + t d along the normal, and
/// returns the normal there, pointing away from the axis. A point on the axis (impossible for
/// a true side hit) stays and gets (0, 0, 1).
inline Normal3 onto_side(Point3& p, double distance, double radius) {
    if (!(distance > 0.0)) return Normal3(0.0, 0.0, 1.0);
    // The unit radial direction first: normalising p itself would underflow for a radius of
    // 1e-300 (hypot does not).
    const Normal3 radial(p.x() / distance, 0.0, p.z() / distance);
    p.x() = radius * radial.x();
    p.z() = radius * radial.z();
    return radial.normalized();
}

}  // namespace csgrt::detail
