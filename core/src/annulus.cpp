#include "csgrt/core/annulus.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"
#include "flat_shape.h"

namespace csgrt {

Annulus::Annulus(const Point3& center, const Normal3& normal, double inner_radius,
                 double outer_radius, double phi_min, double phi_max)
    : center_(center),
      inner_radius_(inner_radius),
      outer_radius_(outer_radius),
      azimuth_(phi_min, phi_max, "Annulus") {
    require_finite(center, "Annulus", "center");
    frame_ = detail::frame_of_normal(normal, "Annulus");
    require_positive(outer_radius, "Annulus", "outer_radius");
    require(inner_radius >= 0.0 && inner_radius < outer_radius, "Annulus", "inner_radius",
            "in [0, outer_radius)", inner_radius);
}

Aabb Annulus::bounds() const {
    return detail::disk_bounds(center_, frame_.normal, outer_radius_);
}

std::optional<Crossing> Annulus::crossing(const Ray& ray) const {
    double t;
    Vector3 offset;
    if (!detail::plane_offset(ray, center_, frame_.normal, t, offset)) return {};
    // Squared distances against squared radii, as for the disk: no square root.
    const double squared = offset.squaredNorm();
    if (squared > outer_radius_ * outer_radius_ || squared < inner_radius_ * inner_radius_)
        return {};
    if (!azimuth_.is_full() &&
        !azimuth_.contains(offset.dot(frame_.x_axis), offset.dot(frame_.z_axis)))
        return {};
    return Crossing{.t = t};
}

SurfacePoint Annulus::surface_at(const Ray& ray, const HitRecord& record) const {
    const detail::FramePoint p = detail::point_in_frame(ray, record.t, center_, frame_);
    const double r = std::hypot(p.x, p.z);
    const double radial = (r - inner_radius_) / (outer_radius_ - inner_radius_);
    return {
        p.point, frame_.normal,
        Vector2(std::clamp(radial, 0.0, 1.0), azimuth_.fraction(AngleRange::azimuth(p.x, p.z)))};
}

template class detail::LeafShape<Annulus>;

}  // namespace csgrt
