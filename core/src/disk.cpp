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
    Vector3 offset;
    if (!detail::plane_offset(ray, center_, frame_.normal, t, offset)) return {};
    // Compare squared distances: no square root (the point the seed makes).
    if (!(offset.squaredNorm() <= radius_ * radius_)) return {};
    return Crossing{.t = t};
}

SurfacePoint Disk::surface_at(const Ray& ray, const HitRecord& record) const {
    const detail::FramePoint p = detail::point_in_frame(ray, record.t, center_, frame_);
    double phi = std::atan2(p.x, p.z);
    if (phi < 0.0) phi += kTwoPi;
    const double r = std::hypot(p.x, p.z);
    return {p.point, frame_.normal,
            Vector2(std::min(r / radius_, 1.0), std::min(phi / kTwoPi, 1.0))};
}

template class detail::LeafShape<Disk>;

}  // namespace csgrt
