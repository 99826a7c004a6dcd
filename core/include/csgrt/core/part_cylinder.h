#pragma once

#include "csgrt/core/angle_range.h"
#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// The side of the cylinder x^2 + z^2 = radius^2 limited to y in [y_min, y_max] and azimuth
/// phi = atan2(x, z) in [phi_min, phi_max]: a part object as in Suffern, "Ray Tracing from the
/// Ground Up" (2007), ch. 19. An open surface, not a solid; its normal points away from the axis.
///
/// Angles are in radians, phi_min in [0, 2 pi) and phi_min < phi_max <= phi_min + 2 pi. A part
/// that crosses the seam phi = 0 = 2 pi is written with phi_max > 2 pi: [3 pi / 2, 5 pi / 2]
/// is the quarter around +z. Both limits are included.
///
/// uv: ((phi - phi_min) / (phi_max - phi_min), (y - y_min) / (y_max - y_min)), with phi taken
/// in [phi_min, phi_min + 2 pi). A ray lying in the surface (parallel to the axis at exactly the
/// radius) misses it, as it misses an open Cylinder.
class PartCylinder final : public detail::LeafShape<PartCylinder> {
public:
    /// Throws InvalidParameter unless radius > 0 and finite, y_min < y_max both finite, and the
    /// angles are as above.
    PartCylinder(double radius, double y_min, double y_max, double phi_min, double phi_max);

    std::string_view kind() const override { return "part_cylinder"; }
    /// The box of the arc (not of the whole cylinder), padded by a few ulps of the radius.
    Aabb bounds() const override { return bounds_; }

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest point in [t_min, t_max] where the ray crosses the kept part of the side.
    std::optional<Crossing> crossing(const Ray& ray) const;

    double radius() const { return radius_; }
    double y_min() const { return y_min_; }
    double y_max() const { return y_max_; }
    /// The azimuth limits [phi_min, phi_max], seam included.
    const AngleRange& azimuth() const { return azimuth_; }

private:

    double radius_;
    double y_min_;
    double y_max_;
    AngleRange azimuth_;
    Aabb bounds_;
};

extern template class detail::LeafShape<PartCylinder>;

}  // namespace csgrt
