#include "csgrt/core/disk.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"
#include "flat_shape.h"

namespace csgrt {

Disk::Disk(const Point3& center, const Normal3& normal, double radius)
    : center_(center), radius_(radius) {
    require_finite(center, "Disk", "center");
    frame_ = detail::frame_of_normal(normal, "Disk");
    require_positive(radius, "Disk", "radius");
}

Aabb Disk::bounds() const {
    return detail::disk_bounds(center_, frame_.normal, radius_);
}

std::optional<Crossing> Disk::crossing(const Ray& ray) const {
    double t;
    if (!detail::plane_crossing(ray, center_, frame_.normal, t) || !ray.in_range(t)) return {};
    // Compare squared distances: no square root (the point the seed makes). The offset is
    // formed as (o - c) + t d, which keeps it accurate when o and c are large but close.
    const Vector3 offset = (ray.origin - center_) + t * ray.direction;
    if (!(offset.squaredNorm() <= radius_ * radius_)) return {};
    return Crossing{.t = t};
}

Hit Disk::finish(const Ray& ray, const HitRecord& record) const {
    Hit hit;
    hit.t = record.t;
    const Vector3 offset = (ray.origin - center_) + record.t * ray.direction;
    const Vector3 local = frame_.to_local(offset);
    // Back onto the plane: drop the normal component that rounding left.
    hit.point = center_ + local.x() * frame_.x_axis + local.z() * frame_.z_axis;
    hit.geometric_normal = frame_.normal;
    hit.shading_normal = frame_.normal;
    double phi = std::atan2(local.x(), local.z());
    if (phi < 0.0) phi += kTwoPi;
    const double r = std::hypot(local.x(), local.z());
    hit.uv = Vector2(std::min(r / radius_, 1.0), std::min(phi / kTwoPi, 1.0));
    hit.shape = this;
    hit.primitive_id = record.primitive;
    hit.front_face = ray.direction.dot(frame_.normal) < 0.0;
    return hit;
}

template class detail::LeafShape<Disk>;

}  // namespace csgrt
