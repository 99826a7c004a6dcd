#pragma once

#include "csgrt/core/angle_range.h"
#include "csgrt/core/plane.h"
#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// The part disk / annulus: points of the plane through `center` with normal `normal`
/// (normalised) at distance r in [inner_radius, outer_radius] from the center and azimuth phi
/// in [phi_min, phi_max] (AngleRange rules: may wrap past 2 pi). phi = atan2(x, z) is
/// measured in `frame()`, so for normal +y it is the y-up azimuth. inner_radius 0 gives a part
/// disk, the full range [0, 2 pi] a plain annulus. Not a solid.
///
/// Conventions: both rims and both radial edges belong to it; the center of a part disk belongs
/// to every azimuth; a ray parallel to the plane never hits; the normal is the one given;
/// uv = ((r - inner) / (outer - inner), where phi lies in the range), so a full-range annulus
/// with inner radius 0 has the Disk's uv.
class Annulus final : public detail::LeafShape<Annulus> {
public:
    /// Throws InvalidParameter unless center is finite, normal finite and non-zero,
    /// 0 <= inner_radius < outer_radius < infinity and the azimuth range is valid.
    Annulus(const Point3& center, const Normal3& normal, double inner_radius, double outer_radius,
            double phi_min = 0.0, double phi_max = kTwoPi);

    std::string_view kind() const override { return "annulus"; }
    /// The bounds of the outer disk (not trimmed by the azimuth range).
    Aabb bounds() const override;

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The point in [t_min, t_max] where the ray crosses the annulus, if any.
    std::optional<Crossing> crossing(const Ray& ray) const;

    const Point3& center() const { return center_; }
    /// The unit normal.
    const Normal3& normal() const { return frame_.normal; }
    const SurfaceFrame& frame() const { return frame_; }
    double inner_radius() const { return inner_radius_; }
    double outer_radius() const { return outer_radius_; }
    const AngleRange& azimuth() const { return azimuth_; }

private:

    Point3 center_;
    SurfaceFrame frame_;
    double inner_radius_;
    double outer_radius_;
    AngleRange azimuth_;
};

extern template class detail::LeafShape<Annulus>;

}  // namespace csgrt
