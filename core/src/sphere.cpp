#include "csgrt/core/sphere.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {

Sphere::Sphere(const Point3& center, double radius) : center_(center), radius_(radius) {
    require_finite(center, "Sphere", "center");
    require_positive(radius, "Sphere", "radius");
}

Aabb Sphere::bounds() const {
    return Aabb(center_ - Vector3::Constant(radius_), center_ + Vector3::Constant(radius_));
}

bool Sphere::line_roots(const Ray& ray, double& t0, double& t1) const {
    // a t^2 + 2 b t + c = 0 with the two reformulations of Haines, Guenther and Akenine-Moeller,
    // "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems 2019, ch. 7.
    const Vector3 f = ray.origin - center_;
    const Vector3& d = ray.direction;
    const double a = d.squaredNorm();
    const double b = f.dot(d);
    const double c = f.squaredNorm() - radius_ * radius_;
    // The discriminant b^2 - a c equals a (r^2 - |f - (b/a) d|^2): the squared distance from
    // the center to the line, which does not cancel catastrophically for small, far spheres.
    const Vector3 to_line = f - (b / a) * d;
    const double discriminant = a * (radius_ * radius_ - to_line.squaredNorm());
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

bool Sphere::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch&) const {
    double t0, t1;
    if (!line_roots(ray, t0, t1)) return false;
    const double t = ray.in_range(t0) ? t0 : t1;
    if (!ray.in_range(t)) return false;
    record = HitRecord{.t = t, .shape = this, .primitive = 0};
    return true;
}

bool Sphere::any_hit(const Ray& ray, QueryScratch&) const {
    double t0, t1;
    return line_roots(ray, t0, t1) && (ray.in_range(t0) || ray.in_range(t1));
}

void Sphere::find_spans(const Ray& ray, SpanList& spans, QueryScratch&) const {
    spans.clear();
    double t0, t1;
    if (!line_roots(ray, t0, t1) || t1 < ray.t_min || t0 > ray.t_max) return;
    spans.push_back(Span{HitRecord{.t = t0, .shape = this, .primitive = 0},
                         HitRecord{.t = t1, .shape = this, .primitive = 0}});
}

bool Sphere::contains(const Point3& p) const {
    return (p - center_).squaredNorm() < radius_ * radius_;
}

Hit Sphere::finish(const Ray& ray, const HitRecord& record) const {
    Hit hit;
    hit.t = record.t;
    Vector3 local = ray.at(record.t) - center_;
    // Project back onto the sphere: removes the rounding of o + t d along the normal.
    local *= radius_ / local.norm();
    hit.point = center_ + local;
    hit.geometric_normal = local / radius_;
    hit.shading_normal = hit.geometric_normal;
    double phi = std::atan2(local.x(), local.z());
    if (phi < 0.0) phi += kTwoPi;
    const double theta = std::acos(std::clamp(local.y() / radius_, -1.0, 1.0));
    hit.uv = Vector2(phi / kTwoPi, 1.0 - theta / kPi);
    hit.shape = this;
    hit.primitive_id = record.primitive;
    hit.front_face = ray.direction.dot(hit.geometric_normal) < 0.0;
    return hit;
}

}  // namespace csgrt
