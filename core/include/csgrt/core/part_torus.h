#pragma once

#include "csgrt/core/angle_range.h"
#include "csgrt/core/torus.h"

namespace csgrt {

/// The part of a torus's surface (Torus: centred at the origin, axis +y) whose angles lie in
/// [phi_min, phi_max] around the y axis and [theta_min, theta_max] around the tube, in
/// radians and in Torus's parameterisation (phi = atan2(x, z); theta = atan2(y, rho - R): 0 on
/// the outer equator, pi / 2 on top). A part object (Suffern, "Ray Tracing from the Ground
/// Up", 2007, ch. 19): an open surface, not a solid.
///
/// Both ranges follow AngleRange's rules (as PartCylinder and PartSphere do): min in
/// [0, 2 pi) and min < max <= min + 2 pi, so a range crossing the seam 0 = 2 pi runs past
/// 2 pi: theta in [7 pi / 4, 9 pi / 4] is the outer band around the equator; max = min + 2 pi
/// keeps every angle. Both ends are included. A ray through a removed part goes on to the next
/// crossing that is kept.
///
/// uv = (fraction of the phi range, fraction of the theta range): [0, 1]^2 over the part.
class PartTorus final : public detail::LeafShape<PartTorus> {
public:
    /// Throws InvalidParameter unless 0 < minor_radius < major_radius (both finite) and both
    /// ranges follow the rules above.
    PartTorus(double major_radius, double minor_radius, double phi_min, double phi_max,
              double theta_min, double theta_max);

    std::string_view kind() const override { return "part_torus"; }
    /// The box of the part: from the ranges of the angles' sines and cosines, padded by 32
    /// ulps of R + r.
    Aabb bounds() const override { return bounds_; }

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest root in [t_min, t_max] whose surface point the angle limits keep.
    std::optional<Crossing> crossing(const Ray& ray) const;

    const Torus& torus() const { return torus_; }

    /// Whether the surface point nearest to p (off the y axis) is part of this surface.
    bool keeps(const Point3& p) const;

private:
    Torus torus_;
    AngleRange phi_range_;
    /// theta = atan2(y, rho - R) is the azimuth of the point (y, rho - R), so the same class
    /// serves around the tube.
    AngleRange theta_range_;
    Aabb bounds_;
};

extern template class detail::LeafShape<PartTorus>;

}  // namespace csgrt
