#include "csgrt/core/plane.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"
#include "flat_shape.h"

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
    frame_ = detail::frame_of_normal(normal, "Plane");
}

std::optional<Crossing> Plane::crossing(const Ray& ray) const {
    double t;
    if (!detail::plane_crossing(ray, point_, frame_.normal, t) || !ray.in_range(t)) return {};
    return Crossing{.t = t};
}

SurfacePoint Plane::surface_at(const Ray& ray, const HitRecord& record) const {
    Vector3 offset = ray.at(record.t) - point_;
    const Point3 point = detail::onto_plane(point_, offset, frame_.normal);
    return {point, frame_.normal,
            Vector2(wrap_unit(offset.dot(frame_.x_axis)), wrap_unit(offset.dot(frame_.z_axis)))};
}

template class detail::LeafShape<Plane>;

}  // namespace csgrt
