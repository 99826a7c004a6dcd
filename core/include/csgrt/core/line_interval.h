#pragma once

#include <cmath>
#include <cstdint>

#include "csgrt/core/math.h"
#include "csgrt/core/polynomial.h"
#include "csgrt/core/ray.h"

// The piece of a ray's line inside a solid of revolution, built from intervals: the cylinder,
// cone and part objects cut an infinite solid by a slab and take the overlap (Roth, "Ray
// Casting for Modeling Solids", 1982), which makes their rims watertight by construction.

namespace csgrt {

namespace detail {

/// The closed part [t0, t1] of a ray's line inside a solid, with the surface each end lies on.
/// Either end may be infinite (not a crossing); an empty interval has t0 > t1.
struct LineInterval {
    double t0 = kInfinity;
    double t1 = -kInfinity;
    std::uint32_t surface0 = 0;
    std::uint32_t surface1 = 0;

    bool empty() const { return !(t0 <= t1); }
};

/// The ray's line inside the infinite solid cylinder x^2 + z^2 <= radius^2 (object space, any
/// direction length); both ends are labelled `side`. Uses the cancellation-free quadratic after
/// moving a far origin to the line's closest approach to the axis, so t keeps a relative error
/// of a few ulps for origins millions of radii away.
inline LineInterval infinite_cylinder_interval(const Ray& ray, double radius, std::uint32_t side) {
    LineInterval line;
    line.surface0 = line.surface1 = side;
    double x = ray.origin.x();
    double z = ray.origin.z();
    const double dx = ray.direction.x();
    const double dz = ray.direction.z();
    const double a = dx * dx + dz * dz;
    const double radius_squared = radius * radius;
    if (a == 0.0) {
        // Parallel to the axis: inside (or on the side) along the whole line, or nowhere.
        if (x * x + z * z - radius_squared <= 0.0) {
            line.t0 = -kInfinity;
            line.t1 = kInfinity;
        }
        return line;
    }
    // A far origin makes b^2 and a c huge and nearly equal, so their difference (the squared
    // distance of the line from the axis, in disguise) loses its digits. Moving the origin along
    // the line to its closest approach keeps every term of the size of the radius; the shift
    // is added back to t, one rounding. Moving costs ~2 u |o| per coordinate, a perturbation
    // of the line as small as its own representation error. The same idea as Haines, Guenther
    // and Akenine-Moeller, "Precision Improvements for Ray/Sphere Intersection", Ray Tracing
    // Gems 2019, and POV-Ray's torus. (Plain products rather than std::fma: without -mfma
    // each fma is a libm call, and the bound above does not need them.)
    double shift = 0.0;
    if (x * x + z * z > 4.0 * radius_squared) {
        shift = -(x * dx + z * dz) / a;
        x += shift * dx;
        z += shift * dz;
    }
    const double b = x * dx + z * dz;
    const double c = x * x + z * z - radius_squared;
    double roots[2];
    if (solve_quadratic(a, 2.0 * b, c, roots) < 2) return line;
    line.t0 = shift + roots[0];
    line.t1 = shift + roots[1];
    return line;
}

/// The ray's line between the planes y = lower and y = upper (lower <= upper), each end
/// labelled with its plane's surface. A ray parallel to the planes is inside everywhere (the
/// closed slab) or nowhere.
inline LineInterval slab_interval(const Ray& ray, double lower, double upper, std::uint32_t lower_surface,
                           std::uint32_t upper_surface) {
    LineInterval slab;
    const double origin = ray.origin.y();
    const double direction = ray.direction.y();
    if (direction == 0.0) {
        if (lower <= origin && origin <= upper) {
            slab.t0 = -kInfinity;
            slab.t1 = kInfinity;
            slab.surface0 = lower_surface;
            slab.surface1 = upper_surface;
        }
        return slab;
    }
    const double t_lower = (lower - origin) / direction;
    const double t_upper = (upper - origin) / direction;
    if (direction > 0.0) {
        slab = LineInterval{t_lower, t_upper, lower_surface, upper_surface};
    } else {
        slab = LineInterval{t_upper, t_lower, upper_surface, lower_surface};
    }
    return slab;
}

/// The overlap of two intervals: the later entry and the earlier exit, each with its surface;
/// ties keep `a`'s surface.
inline LineInterval overlap(const LineInterval& a, const LineInterval& b) {
    LineInterval both;
    if (a.t0 >= b.t0) {
        both.t0 = a.t0;
        both.surface0 = a.surface0;
    } else {
        both.t0 = b.t0;
        both.surface0 = b.surface0;
    }
    if (a.t1 <= b.t1) {
        both.t1 = a.t1;
        both.surface1 = a.surface1;
    } else {
        both.t1 = b.t1;
        both.surface1 = b.surface1;
    }
    return both;
}

/// The nearest point in [t_min, t_max] where the ray crosses the side of an open surface of
/// revolution limited to `slab`: a finite end of `side` inside the slab, with its label.
inline bool nearest_open_surface_hit(const Ray& ray, const LineInterval& side, const LineInterval& slab,
                              double& t, std::uint32_t& surface) {
    // The ends of the inside interval are where the line crosses the surface; infinite ends
    // (a line along the axis, or lying in the surface) are not crossings.
    const double ends[2] = {side.t0, side.t1};
    const std::uint32_t surfaces[2] = {side.surface0, side.surface1};
    for (int i = 0; i < 2; ++i) {
        if (std::isfinite(ends[i]) && slab.t0 <= ends[i] && ends[i] <= slab.t1 &&
            ray.in_range(ends[i])) {
            t = ends[i];
            surface = surfaces[i];
            return true;
        }
    }
    return false;
}

}  // namespace detail

}  // namespace csgrt
