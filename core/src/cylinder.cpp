#include "csgrt/core/cylinder.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/angle_range.h"
#include "csgrt/core/error.h"
#include "csgrt/core/polynomial.h"
#include "solid_interval.h"

namespace csgrt {

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

std::optional<Crossing> Cylinder::crossing(const Ray& ray) const {
    const detail::LineInterval side = detail::infinite_cylinder_interval(ray, radius_, kSide);
    if (side.empty()) return {};
    const detail::LineInterval slab =
        detail::slab_interval(ray, y_min_, y_max_, kBottomCap, kTopCap);
    if (!capped_) {
        Crossing crossing;
        if (!detail::nearest_open_surface_hit(ray, side, slab, crossing.t, crossing.primitive))
            return {};
        return crossing;
    }
    // The solid is the infinite solid cylinder cut by the slab: its span is the overlap of the
    // two intervals, so the rim is watertight by construction (no point-in-disk test).
    return detail::first_crossing(detail::overlap(side, slab), ray);
}

void Cylinder::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    count_solve(scratch, *this);
    spans.clear();
    if (!capped_) return;
    detail::push_span(
        detail::overlap(detail::infinite_cylinder_interval(ray, radius_, kSide),
                        detail::slab_interval(ray, y_min_, y_max_, kBottomCap, kTopCap)),
        ray, this, spans);
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
            // The unit radial direction first: normalising p itself would underflow for a
            // radius of 1e-300 (hypot does not).
            const Normal3 radial(p.x() / distance, 0.0, p.z() / distance);
            p.x() = radius_ * radial.x();
            p.z() = radius_ * radial.z();
            hit.geometric_normal = radial.normalized();
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

template class detail::LeafShape<Cylinder>;

}  // namespace csgrt
