#pragma once

#include <vector>

#include "csgrt/core/hit.h"

namespace csgrt {

/// One interval of the ray inside a solid: from the surface it enters through to the surface it
/// leaves through (Roth, "Ray Casting for Modeling Solids", CGIP 18, 1982). enter.t <= exit.t;
/// a tangent ray gives enter.t == exit.t. An end with a null `shape` is unbounded (t = ±inf):
/// the ray's line never crosses a surface on that side.
struct Span {
    HitRecord enter;
    HitRecord exit;
};

/// Spans sorted by t, pairwise disjoint (a list may touch end to start).
using SpanList = std::vector<Span>;

}  // namespace csgrt
