#include "csgrt/core/sphere.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {

Sphere::Sphere(const Point3& center, double radius) : center_(center), radius_(radius) {
    require_finite(center, "Sphere", "center");
    require_positive(radius, "Sphere", "radius");
    exponent_ = std::ilogb(radius);
    scale_ = std::ldexp(1.0, -exponent_);
    moderate_ = exponent_ >= -200 && exponent_ <= 200;
}

Aabb Sphere::bounds() const {
    return Aabb(center_ - Vector3::Constant(radius_), center_ + Vector3::Constant(radius_));
}

namespace {

/// The roots of |f + t d| = radius, f = origin - center.
bool quadratic_roots(const Vector3& f, const Vector3& d, double radius, double& t0, double& t1) {
    // a t^2 + 2 b t + c = 0 with the two reformulations of Haines, Guenther and Akenine-Moeller,
    // "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems 2019, ch. 7.
    const double a = d.squaredNorm();
    const double b = f.dot(d);
    const double c = f.squaredNorm() - radius * radius;
    // The discriminant b^2 - a c equals a (r^2 - |f - (b/a) d|^2): the squared distance from
    // the center to the line, which does not cancel catastrophically for small, far spheres.
    const Vector3 to_line = f - (b / a) * d;
    const double discriminant = a * (radius * radius - to_line.squaredNorm());
    if (!(discriminant >= 0.0)) return false;
    // q has the sign of -b, so b + sign(b) sqrt(disc) never cancels; t0 t1 = c / a gives the
    // other root.
    const double q = -(b + std::copysign(std::sqrt(discriminant), b));
    if (q == 0.0) {
        t0 = t1 = 0.0;  // b = 0 and a tangent at t = 0: the origin is on the sphere
        return true;
    }
    t0 = c / q;
    t1 = q / a;
    if (t0 > t1) std::swap(t0, t1);
    return true;
}

}  // namespace

bool Sphere::line_roots(const Ray& ray, double& t0, double& t1) const {
    const Vector3 f = ray.origin - center_;
    const double a = ray.direction.squaredNorm();
    if (moderate_ && a >= 0x1p-400 && a <= 0x1p400)
        return quadratic_roots(f, ray.direction, radius_, t0, t1);
    // A radius or direction length far from 1 would underflow or overflow in the squares (a
    // sphere of radius 1e-300 has r^2 = 0). Rescale by powers of two, exactly: the sphere to
    // radius in [1, 2) (f s, r s), the direction to its largest component in [1, 2) (d 2^-k).
    // Then f s + tau d 2^-k = s (f + t d) for t = tau 2^(e - k), s = 2^-e.
    const double largest = ray.direction.cwiseAbs().maxCoeff();
    // An invalid direction (zero, NaN, infinite) has no scale; the raw queries must still
    // return, without the integer overflow ilogb's error value would cause below.
    if (!(largest > 0.0 && largest < kInfinity) || !is_finite(ray.direction)) return false;
    const int direction_exponent = std::ilogb(largest);
    const Vector3 direction = ray.direction * std::ldexp(1.0, -direction_exponent);
    if (!quadratic_roots(f * scale_, direction, radius_ * scale_, t0, t1)) return false;
    t0 = std::ldexp(t0, exponent_ - direction_exponent);
    t1 = std::ldexp(t1, exponent_ - direction_exponent);
    return true;
}

std::optional<Crossing> Sphere::crossing(const Ray& ray) const {
    double t0, t1;
    if (!line_roots(ray, t0, t1)) return {};
    const double t = ray.in_range(t0) ? t0 : t1;
    if (!ray.in_range(t)) return {};
    return Crossing{.t = t};
}

void Sphere::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    count_solve(scratch, *this);
    spans.clear();
    double t0, t1;
    if (!line_roots(ray, t0, t1) || t1 < ray.t_min || t0 > ray.t_max) return;
    spans.push_back(Span{HitRecord{.t = t0, .shape = this, .primitive = 0},
                         HitRecord{.t = t1, .shape = this, .primitive = 0}});
}

bool Sphere::contains(const Point3& p) const {
    // In units of the rescaled radius, so that tiny and huge spheres do not underflow or
    // overflow the squares.
    const double radius = radius_ * scale_;
    return ((p - center_) * scale_).squaredNorm() < radius * radius;
}

SurfacePoint Sphere::surface_at(const Ray& ray, const HitRecord& record) const {
    // Project back onto the sphere: removes the rounding of o + t d along the normal.
    const Normal3 normal = unit_along(ray.at(record.t) - center_);
    double phi = std::atan2(normal.x(), normal.z());
    if (phi < 0.0) phi += kTwoPi;
    const double theta = std::acos(std::clamp(normal.y(), -1.0, 1.0));
    return {center_ + radius_ * normal, normal, Vector2(phi / kTwoPi, 1.0 - theta / kPi)};
}

template class detail::LeafShape<Sphere>;

}  // namespace csgrt
