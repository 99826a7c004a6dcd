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

SurfacePoint Cylinder::surface_at(const Ray& ray, const HitRecord& record) const {
    Point3 p = ray.at(record.t);
    const double phi = AngleRange::azimuth(p.x(), p.z());
    const double distance = std::hypot(p.x(), p.z());
    if (record.primitive != kSide) {
        const bool top = record.primitive == kTopCap;
        return detail::cap_point(p, distance, top ? y_max_ : y_min_, top, radius_);
    }
    const Normal3 normal = detail::onto_side(p, distance, radius_);
    return {p, normal,
            Vector2(phi / kTwoPi, std::clamp((p.y() - y_min_) / (y_max_ - y_min_), 0.0, 1.0))};
}

template class detail::LeafShape<Cylinder>;

}  // namespace csgrt
