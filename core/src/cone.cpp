#include "csgrt/core/cone.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/angle_range.h"
#include "csgrt/core/error.h"
#include "csgrt/core/polynomial.h"
#include "solid_interval.h"

namespace csgrt {

Cone::Cone(double base_radius, double top_radius, double height, bool capped)
    : base_radius_(base_radius), top_radius_(top_radius), height_(height), capped_(capped) {
    require(base_radius >= 0.0 && base_radius < kInfinity, "Cone", "base_radius", ">= 0 and finite",
            base_radius);
    require(top_radius >= 0.0 && top_radius < kInfinity, "Cone", "top_radius", ">= 0 and finite",
            top_radius);
    require(base_radius > 0.0 || top_radius > 0.0, "Cone", "top_radius",
            "> 0 when base_radius is 0", top_radius);
    require_positive(height, "Cone", "height");
    slope_ = (top_radius_ - base_radius_) / height_;
    // The side normal is (cos, -slope, sin) / sqrt(1 + slope^2) around the axis.
    normal_radial_ = 1.0 / std::sqrt(1.0 + slope_ * slope_);
    normal_y_ = -slope_ * normal_radial_;
    pointed_ = base_radius_ == 0.0 || top_radius_ == 0.0;
    apex_ = Point3(0.0, top_radius_ == 0.0 ? height_ : 0.0, 0.0);
    apex_normal_ = Normal3(0.0, slope_ <= 0.0 ? 1.0 : -1.0, 0.0);
    center_ = Point3(0.0, 0.5 * height_, 0.0);
    size_ = std::hypot(std::max(base_radius_, top_radius_), 0.5 * height_);
}

Aabb Cone::bounds() const {
    const double radius = std::max(base_radius_, top_radius_);
    return Aabb(Point3(-radius, 0.0, -radius), Point3(radius, height_, radius));
}

detail::LineInterval Cone::side_interval(const Ray& ray) const {
    detail::LineInterval line;
    line.surface0 = line.surface1 = kSide;
    const Vector3& d = ray.direction;
    Point3 o = ray.origin;
    // A far origin makes the quadratic's terms huge and nearly cancelling; moving it along the
    // line to the closest approach to the cone's center keeps them of the cone's size (as for
    // Cylinder and POV-Ray's torus), and the shift is added back to t.
    double shift = 0.0;
    const Vector3 to_center = center_ - o;
    if (to_center.squaredNorm() > 4.0 * size_ * size_) {
        shift = to_center.dot(d) / d.squaredNorm();
        o += shift * d;
    }
    // F(t) = x^2 + z^2 - rho(y)^2 along the line, with rho(y(t)) = radius + rate t; rho < 0 is
    // the other nappe. That nappe lies beyond the apex plane, which is a slab plane or outside
    // the slab, so a piece of the line inside it never survives the slab: only a line that
    // runs through both nappes (a < 0) needs choosing.
    const double radius = base_radius_ + slope_ * o.y();
    const double rate = slope_ * d.y();
    const double a = d.x() * d.x() + d.z() * d.z() - rate * rate;
    const double b = o.x() * d.x() + o.z() * d.z() - radius * rate;
    const double c = o.x() * o.x() + o.z() * o.z() - radius * radius;
    // The line inside from t on, or up to t.
    const auto from = [&line](double t) {
        line.t0 = t;
        line.t1 = kInfinity;
        return line;
    };
    const auto until = [&line](double t) {
        line.t0 = -kInfinity;
        line.t1 = t;
        return line;
    };
    double roots[2];
    const int count = solve_quadratic(a, 2.0 * b, c, roots);
    if (count == 2) {
        if (a > 0.0) {
            // Inside between the roots.
            line.t0 = shift + roots[0];
            line.t1 = shift + roots[1];
            return line;
        }
        // Steeper than the side: inside beyond each root, one piece per nappe; ours is the one
        // toward which rho grows.
        return rate > 0.0 ? from(shift + roots[1]) : until(shift + roots[0]);
    }
    if (count == 1) {
        // a == 0: parallel to a generator, inside on one side of the one crossing.
        return b < 0.0 ? from(shift + roots[0]) : until(shift + roots[0]);
    }
    // No crossing, yet inside all along when a < 0 (rounding has hidden the double root of a
    // line through the apex), or when a == b == 0 and c <= 0 (a line lying in the side, which
    // passes the apex, or one parallel to the axis inside a cylinder-like cone).
    if (!(a < 0.0 || (a == 0.0 && c <= 0.0))) return line;
    // Then a == 0 means a vertical line, inside (or on) a cylinder-like cone.
    if (rate == 0.0) return from(-kInfinity);
    // Our nappe is the side of the apex plane where rho > 0.
    const double t_apex = shift - radius / rate;
    if (rate > 0.0) {
        line.surface0 = kApex;
        return from(t_apex);
    }
    line.surface1 = kApex;
    return until(t_apex);
}

bool Cone::apex_on_line(const Ray& ray, double& t) const {
    const Vector3 to_apex = apex_ - ray.origin;
    const double along = to_apex.dot(ray.direction) / ray.direction.squaredNorm();
    const Vector3 miss = to_apex - along * ray.direction;
    // For a line exactly through the apex the computed miss is rounding alone: about
    // gamma(10) |to_apex| per coordinate (the difference, the dot product, the division and the
    // product), so gamma(18) |to_apex| bounds its length.
    if (!(miss.squaredNorm() <= square(gamma(18) * to_apex.norm()))) return false;
    t = along;
    return true;
}

double Cone::apex_reach(const Ray& ray) const {
    // The quadratic's double root at the apex is only determined to about sqrt(u).
    return std::sqrt(kUnitRoundoff) * ((apex_ - ray.origin).norm() + size_) / ray.direction.norm();
}

detail::LineInterval Cone::solid_interval(const Ray& ray) const {
    detail::LineInterval span = detail::overlap(
        side_interval(ray), detail::slab_interval(ray, 0.0, height_, kBaseCap, kTopCap));
    // A zero-radius end has no cap: the slab plane meets our nappe only at the apex.
    for (std::uint32_t* surface : {&span.surface0, &span.surface1}) {
        if ((*surface == kBaseCap && base_radius_ == 0.0) ||
            (*surface == kTopCap && top_radius_ == 0.0)) {
            *surface = kApex;
        }
    }
    double t_apex;
    if (!pointed_ || !apex_on_line(ray, t_apex)) return span;
    // The solid is convex and holds its apex: a line through the apex meets it in a segment
    // containing t_apex. Extend to it, and attribute ends near it to it.
    if (span.empty()) return detail::LineInterval{t_apex, t_apex, kApex, kApex};
    const double reach = apex_reach(ray);
    if (t_apex <= span.t0 + reach) {
        span.t0 = t_apex;
        span.surface0 = kApex;
    }
    if (t_apex >= span.t1 - reach) {
        span.t1 = t_apex;
        span.surface1 = kApex;
    }
    return span;
}

std::optional<Crossing> Cone::crossing(const Ray& ray) const {
    if (capped_) {
        return detail::first_crossing(solid_interval(ray), ray);
    }
    Crossing crossing;
    const bool found = detail::nearest_open_surface_hit(
        ray, side_interval(ray), detail::slab_interval(ray, 0.0, height_, kBaseCap, kTopCap),
        crossing.t, crossing.primitive);
    double t_apex;
    if (pointed_ && apex_on_line(ray, t_apex) && ray.in_range(t_apex) &&
        (!found || t_apex <= crossing.t + apex_reach(ray))) {
        return Crossing{.t = t_apex, .primitive = kApex};
    }
    if (!found) return {};
    return crossing;
}

void Cone::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    count_solve(scratch, *this);
    spans.clear();
    if (!capped_) return;
    detail::push_span(solid_interval(ray), ray, this, spans);
}

bool Cone::contains(const Point3& p) const {
    if (!capped_ || !(p.y() > 0.0 && p.y() < height_)) return false;
    return p.x() * p.x() + p.z() * p.z() < square(radius_at(p.y()));
}

SurfacePoint Cone::surface_at(const Ray& ray, const HitRecord& record) const {
    Point3 p = ray.at(record.t);
    const double distance = std::hypot(p.x(), p.z());
    switch (record.primitive) {
        case kBaseCap:
        case kTopCap: {
            const bool top = record.primitive == kTopCap;
            return detail::cap_point(p, distance, top ? height_ : 0.0, top,
                                     top ? top_radius_ : base_radius_);
        }
        case kSide:
            if (distance > 0.0) {
                const Normal3 normal = Normal3(p.x() / distance * normal_radial_, normal_y_,
                                               p.z() / distance * normal_radial_)
                                           .normalized();
                // Move the point along the normal onto the side: (|xz| - rho(y)) cos(half angle)
                // is its signed distance to the infinite cone there.
                p -= (distance - radius_at(p.y())) * normal_radial_ * normal;
                return {p, normal,
                        Vector2(AngleRange::azimuth(p.x(), p.z()) / kTwoPi,
                                std::clamp(p.y() / height_, 0.0, 1.0))};
            }
            [[fallthrough]];  // on the axis: only the apex of a pointed cone is there
        default:
            return {apex_, apex_normal_, Vector2(0.0, apex_.y() / height_)};
    }
}

template class detail::LeafShape<Cone>;

}  // namespace csgrt
