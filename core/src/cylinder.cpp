#include "csgrt/core/cylinder.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/angle_range.h"
#include "csgrt/core/error.h"
#include "csgrt/core/polynomial.h"

namespace csgrt {

namespace detail {

LineInterval infinite_cylinder_interval(const Ray& ray, double radius, std::uint32_t side) {
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

LineInterval slab_interval(const Ray& ray, double lower, double upper, std::uint32_t lower_surface,
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

LineInterval overlap(const LineInterval& a, const LineInterval& b) {
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

bool nearest_open_surface_hit(const Ray& ray, const LineInterval& side, const LineInterval& slab,
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

Cylinder::Cylinder(double radius, double y_min, double y_max, bool capped)
    : radius_(radius), y_min_(y_min), y_max_(y_max), capped_(capped) {
    require_positive(radius, "Cylinder", "radius");
    require_finite(y_min, "Cylinder", "y_min");
    require_finite(y_max, "Cylinder", "y_max");
    require(y_min < y_max, "Cylinder", "y_max", "> y_min", y_max);
}

Aabb Cylinder::bounds() const {
    return Aabb(Point3(-radius_, y_min_, -radius_), Point3(radius_, y_max_, radius_));
}

bool Cylinder::nearest(const Ray& ray, double& t, std::uint32_t& surface) const {
    const detail::LineInterval side = detail::infinite_cylinder_interval(ray, radius_, kSide);
    if (side.empty()) return false;
    const detail::LineInterval slab =
        detail::slab_interval(ray, y_min_, y_max_, kBottomCap, kTopCap);
    if (!capped_) return detail::nearest_open_surface_hit(ray, side, slab, t, surface);
    // The solid is the infinite solid cylinder cut by the slab: its span is the overlap of the
    // two intervals, so the rim is watertight by construction (no point-in-disk test).
    const detail::LineInterval span = detail::overlap(side, slab);
    if (span.empty()) return false;
    if (ray.in_range(span.t0) && std::isfinite(span.t0)) {
        t = span.t0;
        surface = span.surface0;
        return true;
    }
    if (ray.in_range(span.t1) && std::isfinite(span.t1)) {
        t = span.t1;
        surface = span.surface1;
        return true;
    }
    return false;
}

bool Cylinder::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch&) const {
    double t;
    std::uint32_t surface;
    if (!nearest(ray, t, surface)) return false;
    record = HitRecord{.t = t, .shape = this, .primitive = surface};
    return true;
}

bool Cylinder::any_hit(const Ray& ray, QueryScratch&) const {
    double t;
    std::uint32_t surface;
    return nearest(ray, t, surface);
}

void Cylinder::find_spans(const Ray& ray, SpanList& spans, QueryScratch&) const {
    spans.clear();
    if (!capped_) return;
    const detail::LineInterval span =
        detail::overlap(detail::infinite_cylinder_interval(ray, radius_, kSide),
                        detail::slab_interval(ray, y_min_, y_max_, kBottomCap, kTopCap));
    // A bounded solid has finite span ends; infinite ones only arise from underflowed
    // directions, which cross nothing.
    if (span.empty() || span.t1 < ray.t_min || span.t0 > ray.t_max || !std::isfinite(span.t0) ||
        !std::isfinite(span.t1)) {
        return;
    }
    spans.push_back(Span{HitRecord{.t = span.t0, .shape = this, .primitive = span.surface0},
                         HitRecord{.t = span.t1, .shape = this, .primitive = span.surface1}});
}

bool Cylinder::contains(const Point3& p) const {
    return capped_ && p.x() * p.x() + p.z() * p.z() < radius_ * radius_ && p.y() > y_min_ &&
           p.y() < y_max_;
}

Hit Cylinder::finish(const Ray& ray, const HitRecord& record) const {
    Hit hit;
    hit.t = record.t;
    Point3 p = ray.at(record.t);
    const double phi = AngleRange::azimuth(p.x(), p.z());
    const double distance = std::hypot(p.x(), p.z());
    if (record.primitive == kSide) {
        // Project radially onto the side, which removes the rounding of o + t d along the
        // normal; a point on the axis (impossible for a true side hit) keeps a fixed normal.
        if (distance > 0.0) {
            p.x() *= radius_ / distance;
            p.z() *= radius_ / distance;
            hit.geometric_normal = Normal3(p.x(), 0.0, p.z()).normalized();
        } else {
            hit.geometric_normal = Normal3(0.0, 0.0, 1.0);
        }
        hit.uv = Vector2(phi / kTwoPi, std::clamp((p.y() - y_min_) / (y_max_ - y_min_), 0.0, 1.0));
    } else {
        const bool top = record.primitive == kTopCap;
        p.y() = top ? y_max_ : y_min_;
        hit.geometric_normal = Normal3(0.0, top ? 1.0 : -1.0, 0.0);
        hit.uv = Vector2(phi / kTwoPi, std::min(distance / radius_, 1.0));
    }
    hit.point = p;
    hit.shading_normal = hit.geometric_normal;
    hit.shape = this;
    hit.primitive_id = record.primitive;
    hit.front_face = ray.direction.dot(hit.geometric_normal) < 0.0;
    return hit;
}

}  // namespace csgrt
