#include "csgrt/core/rectangle.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"
#include "csgrt/core/plane.h"
#include "flat_shape.h"

namespace csgrt {

Rectangle::Rectangle(const Point3& corner, const Vector3& edge_a, const Vector3& edge_b)
    : corner_(corner), edge_a_(edge_a), edge_b_(edge_b) {
    require_finite(corner, "Rectangle", "corner");
    require_finite(edge_a, "Rectangle", "edge_a");
    require_finite(edge_b, "Rectangle", "edge_b");
    const double scale_a = edge_a.cwiseAbs().maxCoeff(), scale_b = edge_b.cwiseAbs().maxCoeff();
    require(scale_a > 0.0, "Rectangle", "edge_a", "non-zero", edge_a);
    require(scale_b > 0.0, "Rectangle", "edge_b", "non-zero", edge_b);
    // With a = scale_a a' and b = scale_b b' (components <= 1, so nothing under- or
    // overflows) and m = a' x b': dual_a = (b x m) / (m . m scale_a) and dual_b = (m x a) /
    // (m . m scale_b) satisfy a . dual_a = b . dual_b = 1 and a . dual_b = b . dual_a = 0.
    const Vector3 unit_a = edge_a / scale_a, unit_b = edge_b / scale_b;
    const Vector3 m = unit_a.cross(unit_b);
    const double m_squared = m.squaredNorm();
    require(m_squared > 0.0, "Rectangle", "edge_b", "not parallel to edge_a", edge_b);
    normal_ = detail::normalized_or_zero(m);
    dual_a_ = unit_b.cross(m) / (m_squared * scale_a);
    dual_b_ = m.cross(unit_a) / (m_squared * scale_b);
}

Aabb Rectangle::bounds() const {
    Aabb box(corner_, corner_ + edge_a_);
    box.extend(corner_ + edge_b_);
    box.extend(corner_ + edge_a_ + edge_b_);
    // Each corner is up to two roundings from the true one: widen by two ulps.
    for (int axis = 0; axis < 3; ++axis) {
        box.lower[axis] = next_down(next_down(box.lower[axis]));
        box.upper[axis] = next_up(next_up(box.upper[axis]));
    }
    return box;
}

std::optional<Crossing> Rectangle::crossing(const Ray& ray) const {
    double t;
    Vector3 offset;
    if (!detail::plane_offset(ray, corner_, normal_, t, offset)) return {};
    const double s = offset.dot(dual_a_);
    const double r = offset.dot(dual_b_);
    // Closed: edges and corners belong to the parallelogram.
    if (!(s >= 0.0 && s <= 1.0 && r >= 0.0 && r <= 1.0)) return {};
    return Crossing{.t = t, .u = static_cast<float>(s), .v = static_cast<float>(r)};
}

SurfacePoint Rectangle::surface_at(const Ray& ray, const HitRecord& record) const {
    Vector3 offset = (ray.origin - corner_) + record.t * ray.direction;
    return {detail::onto_plane(corner_, offset, normal_), normal_, detail::record_uv(record)};
}

template class detail::LeafShape<Rectangle>;

}  // namespace csgrt
