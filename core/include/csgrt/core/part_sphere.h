#pragma once

#include <string_view>

#include "csgrt/core/angle_range.h"
#include "csgrt/core/leaf_shape.h"
#include "csgrt/core/sphere.h"

namespace csgrt {

/// The part of the sphere surface |p - center| = radius with azimuth phi = atan2(x, z) in
/// [phi_min, phi_max] and polar angle theta = acos(y / r) in [theta_min, theta_max], measured
/// from +y about the center (the conventions of sphere.h). An open surface: not a solid.
///
/// Conventions: the limits are closed (their circles belong to the surface); a ray through the
/// removed part goes on to the far side; the normal points away from the center whichever side
/// is hit; uv = (fraction of the azimuth range, (theta_max - theta) / (theta_max - theta_min)),
/// so v grows upward as on the sphere.
class PartSphere final : public detail::LeafShape<PartSphere> {
public:
    /// Throws InvalidParameter unless center is finite, radius > 0 and finite, the azimuth
    /// range follows AngleRange's rules and 0 <= theta_min < theta_max <= pi.
    PartSphere(const Point3& center, double radius, double phi_min, double phi_max,
               double theta_min, double theta_max);

    std::string_view kind() const override { return "part_sphere"; }
    /// The box of the polar band (not trimmed by the azimuth range).
    Aabb bounds() const override;

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest point in [t_min, t_max] where the ray crosses the kept part of the sphere.
    std::optional<Crossing> crossing(const Ray& ray) const;

    const Point3& center() const { return sphere_.center(); }
    double radius() const { return sphere_.radius(); }
    const AngleRange& azimuth() const { return azimuth_; }
    double theta_min() const { return theta_min_; }
    double theta_max() const { return theta_max_; }

    /// Whether a point at `offset` from the center (on the sphere up to rounding) lies within
    /// the angle limits.
    bool in_limits(const Vector3& offset) const {
        return offset.y() >= y_low_ && offset.y() <= y_high_ &&
               azimuth_.contains(offset.x(), offset.z());
    }

private:

    Sphere sphere_;
    AngleRange azimuth_;
    double theta_min_;
    double theta_max_;
    // The polar limits as heights above the center, y = r cos(theta), which avoids an acos
    // per hit; +-infinity where there is no limit.
    double y_low_;
    double y_high_;
};

extern template class detail::LeafShape<PartSphere>;

}  // namespace csgrt
