#include "csgrt/core/plane.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {

SurfaceFrame SurfaceFrame::around(const Normal3& n) {
    // z_axis = R z for the rotation R described in the header. Written out, it is
    // (-k nx nz, -s nz, 1 - k nz^2) with s the side of the horizon and k = 1 / (1 + |ny|),
    // which never divides by less than 1.
    const double side = n.y() >= 0.0 ? 1.0 : -1.0;
    const double k = 1.0 / (1.0 + std::abs(n.y()));
    SurfaceFrame frame;
    frame.normal = n;
    frame.z_axis = Vector3(-k * n.x() * n.z(), -side * n.z(), 1.0 - k * n.z() * n.z());
    frame.x_axis = n.cross(frame.z_axis);
    return frame;
}

namespace detail {

Vector3 normalized_or_zero(const Vector3& v) {
    const double largest = v.cwiseAbs().maxCoeff();
    if (!(largest > 0.0) || !std::isfinite(largest)) return Vector3::Zero();
    return (v / largest).normalized();
}

Aabb disk_bounds(const Point3& center, const Normal3& normal, double radius) {
    Aabb box;
    for (int axis = 0; axis < 3; ++axis) {
        // sqrt(1 - n_i^2) as the norm of the other two components, which does not cancel;
        // gamma(4) covers its rounding and the product's, the ulp steps the sums'.
        const double other = std::hypot(normal[(axis + 1) % 3], normal[(axis + 2) % 3]);
        const double reach = radius * std::min(other, 1.0) * (1.0 + gamma(4));
        box.lower[axis] = next_down(center[axis] - reach);
        box.upper[axis] = next_up(center[axis] + reach);
    }
    return box;
}

}  // namespace detail

namespace {

// x - floor(x) in [0, 1): a tiny negative x rounds to 1, which is the same place as 0.
double wrap_unit(double x) {
    const double fraction = x - std::floor(x);
    return fraction < 1.0 ? fraction : 0.0;
}

}  // namespace

Plane::Plane(const Point3& point, const Normal3& normal) : point_(point) {
    require_finite(point, "Plane", "point");
    require_finite(normal, "Plane", "normal");
    const Normal3 unit = detail::normalized_or_zero(normal);
    require(unit.squaredNorm() > 0.0, "Plane", "normal", "non-zero", normal);
    frame_ = SurfaceFrame::around(unit);
}

bool Plane::crossing(const Ray& ray, double& t) const {
    return detail::plane_crossing(ray, point_, frame_.normal, t) && ray.in_range(t);
}

bool Plane::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch&) const {
    double t;
    if (!crossing(ray, t)) return false;
    record = HitRecord{.t = t, .shape = this, .primitive = 0};
    return true;
}

bool Plane::any_hit(const Ray& ray, QueryScratch&) const {
    double t;
    return crossing(ray, t);
}

Hit Plane::finish(const Ray& ray, const HitRecord& record) const {
    Hit hit;
    hit.t = record.t;
    Vector3 offset = ray.at(record.t) - point_;
    // Drop the component along the normal that o + t d picked up by rounding.
    offset -= offset.dot(frame_.normal) * frame_.normal;
    hit.point = point_ + offset;
    hit.geometric_normal = frame_.normal;
    hit.shading_normal = frame_.normal;
    hit.uv = Vector2(wrap_unit(offset.dot(frame_.x_axis)), wrap_unit(offset.dot(frame_.z_axis)));
    hit.shape = this;
    hit.primitive_id = record.primitive;
    hit.front_face = ray.direction.dot(frame_.normal) < 0.0;
    return hit;
}

}  // namespace csgrt
