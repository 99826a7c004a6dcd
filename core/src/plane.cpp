#include "csgrt/core/plane.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {


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

std::optional<Crossing> Plane::crossing(const Ray& ray) const {
    double t;
    if (!detail::plane_crossing(ray, point_, frame_.normal, t) || !ray.in_range(t)) return {};
    return Crossing{.t = t};
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

template class detail::LeafShape<Plane>;

}  // namespace csgrt
