#pragma once

#include "csgrt/core/math.h"

namespace csgrt {

/// A ray o + t d restricted to the closed interval [t_min, t_max]. The direction need not be
/// unit length: instances map rays into object space without renormalising, so the same t
/// names the same point in every space.
struct Ray {
    Point3 origin{0.0, 0.0, 0.0};
    Vector3 direction{0.0, 0.0, 1.0};
    double t_min = 0.0;
    double t_max = kInfinity;

    Point3 at(double t) const { return origin + t * direction; }

    /// True when t lies in [t_min, t_max]; false for NaN.
    bool in_range(double t) const { return t >= t_min && t <= t_max; }
};

/// A ray every query can answer: finite origin, finite non-zero direction, and an interval
/// with t_min <= t_max (t_max may be +infinity, t_min may be -infinity). Queries given any
/// other ray report no hit.
inline bool is_valid(const Ray& ray) {
    return is_finite(ray.origin) && is_finite(ray.direction) && ray.direction.squaredNorm() > 0.0 &&
           ray.t_min <= ray.t_max && !std::isnan(ray.t_min) && !std::isnan(ray.t_max);
}

}  // namespace csgrt
