#pragma once

// What the bounded solids of revolution (cylinder, cone) do with their line interval once
// they have it: the nearest crossing and the span. Private to core/src.

#include <cmath>
#include <optional>

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

}  // namespace csgrt::detail
