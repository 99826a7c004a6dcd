#include "csgrt/core/part_cylinder.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/cylinder.h"
#include "csgrt/core/error.h"
#include "solid_interval.h"

namespace csgrt {

PartCylinder::PartCylinder(double radius, double y_min, double y_max, double phi_min,
                           double phi_max)
    : radius_(radius), y_min_(y_min), y_max_(y_max), azimuth_(phi_min, phi_max, "PartCylinder") {
    require_positive(radius, "PartCylinder", "radius");
    require_finite(y_min, "PartCylinder", "y_min");
    require_finite(y_max, "PartCylinder", "y_max");
    require(y_min < y_max, "PartCylinder", "y_max", "> y_min", y_max);

    // The arc's box: a point of the side is (r sin phi, y, r cos phi).
    double sin_lo, sin_hi, cos_lo, cos_hi;
    azimuth_.sine_cosine_bounds(sin_lo, sin_hi, cos_lo, cos_hi);
    const Aabb arc(Point3(radius_ * sin_lo, y_min_, radius_ * cos_lo),
                   Point3(radius_ * sin_hi, y_max_, radius_ * cos_hi));
    // sin and cos are rounded, and hits are accepted on rounded azimuths: pad so the box
    // holds every point the queries can return.
    const Vector3 pad(16.0 * kUnitRoundoff * radius_, 0.0, 16.0 * kUnitRoundoff * radius_);
    bounds_ = Aabb(arc.lower - pad, arc.upper + pad);
}

std::optional<Crossing> PartCylinder::crossing(const Ray& ray) const {
    const detail::LineInterval side =
        detail::infinite_cylinder_interval(ray, radius_, Cylinder::kSide);
    if (side.empty()) return {};
    const detail::LineInterval slab =
        detail::slab_interval(ray, y_min_, y_max_, Cylinder::kBottomCap, Cylinder::kTopCap);
    // Nearest crossing first; one in the removed sector lets the ray on to the far crossing.
    // Infinite ends (a line along the axis, or lying in the surface) are not crossings.
    for (const double end : {side.t0, side.t1}) {
        if (!std::isfinite(end) || !(slab.t0 <= end && end <= slab.t1) || !ray.in_range(end)) {
            continue;
        }
        const Point3 p = ray.at(end);
        if (azimuth_.contains(p.x(), p.z())) return Crossing{.t = end};
    }
    return {};
}

SurfacePoint PartCylinder::surface_at(const Ray& ray, const HitRecord& record) const {
    Point3 p = ray.at(record.t);
    const Normal3 normal = detail::onto_side(p, std::hypot(p.x(), p.z()), radius_);
    return {p, normal,
            Vector2(azimuth_.fraction(AngleRange::azimuth(p.x(), p.z())),
                    std::clamp((p.y() - y_min_) / (y_max_ - y_min_), 0.0, 1.0))};
}

template class detail::LeafShape<PartCylinder>;

}  // namespace csgrt
