#pragma once

#include <string_view>

#include "csgrt/core/shape.h"
#include "csgrt/core/sphere.h"

namespace csgrt {

/// A closed azimuth interval [phi_min, phi_max] (radians) of a part object, with the azimuth
/// phi = atan2(x, z) in [0, 2 pi) of the y-up convention.
///
/// phi_min lies in [0, 2 pi) and phi_min < phi_max <= phi_min + 2 pi (the rule PartCylinder
/// follows too), so a range may run past 2 pi and then wraps through phi = 0: [3 pi / 2,
/// 5 pi / 2] is the half facing +z. phi_max == phi_min + 2 pi is the full circle. Both ends
/// belong to the range, and a point on the axis (x = z = 0) belongs to every azimuth. The seam
/// phi = 0 = 2 pi is no boundary: a point with x = 0, z > 0 is in [0, a] and in [b, 2 pi]
/// alike.
class AzimuthRange {
public:
    /// Throws InvalidParameter naming `what` and phi_min or phi_max unless they follow the
    /// rules above.
    AzimuthRange(double phi_min, double phi_max, std::string_view what);

    double phi_min() const { return phi_min_; }
    double phi_max() const { return phi_max_; }
    bool is_full() const { return full_; }

    /// Whether the azimuth of the point (x, z) lies in the range.
    bool contains(double x, double z) const {
        if (full_ || (x == 0.0 && z == 0.0)) return true;
        return offset_from_min(azimuth(x, z)) <= extent_;
    }

    /// Where azimuth phi lies in the range: 0 at phi_min, 1 at phi_max; a phi just outside
    /// (by rounding) gives the nearer end.
    double fraction(double phi) const;

    /// atan2(x, z) wrapped to [0, 2 pi] (2 pi only when a tiny negative x rounds up to it).
    static double azimuth(double x, double z);

private:
    /// phi - phi_min reduced into [0, 2 pi).
    double offset_from_min(double phi) const {
        double offset = phi - phi_min_;
        if (offset < 0.0) offset += kTwoPi;
        if (offset >= kTwoPi) offset -= kTwoPi;
        return offset;
    }

    double phi_min_;
    double phi_max_;
    double extent_;
    bool full_;
};

/// The part of the sphere surface |p - center| = radius with azimuth phi = atan2(x, z) in
/// [phi_min, phi_max] and polar angle theta = acos(y / r) in [theta_min, theta_max], measured
/// from +y about the center (the conventions of sphere.h). An open surface: not a solid.
///
/// Conventions: the limits are closed (their circles belong to the surface); a ray through the
/// removed part goes on to the far side; the normal points away from the center whichever side
/// is hit; uv = (fraction of the azimuth range, (theta_max - theta) / (theta_max - theta_min)),
/// so v grows upward as on the sphere.
class PartSphere final : public Shape {
public:
    /// Throws InvalidParameter unless center is finite, radius > 0 and finite, the azimuth
    /// range follows AzimuthRange's rules and 0 <= theta_min < theta_max <= pi.
    PartSphere(const Point3& center, double radius, double phi_min, double phi_max,
               double theta_min, double theta_max);

    std::string_view kind() const override { return "part_sphere"; }
    /// The box of the polar band (not trimmed by the azimuth range).
    Aabb bounds() const override;

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    Hit finish(const Ray& ray, const HitRecord& record) const override;

    const Point3& center() const { return sphere_.center(); }
    double radius() const { return sphere_.radius(); }
    const AzimuthRange& azimuth() const { return azimuth_; }
    double theta_min() const { return theta_min_; }
    double theta_max() const { return theta_max_; }

    /// Whether a point at `offset` from the center (on the sphere up to rounding) lies within
    /// the angle limits.
    bool in_limits(const Vector3& offset) const {
        return offset.y() >= y_low_ && offset.y() <= y_high_ &&
               azimuth_.contains(offset.x(), offset.z());
    }

private:
    bool first_crossing(const Ray& ray, double& t) const;

    Sphere sphere_;
    AzimuthRange azimuth_;
    double theta_min_;
    double theta_max_;
    // The polar limits as heights above the center, y = r cos(theta), which avoids an acos
    // per hit; +-infinity where there is no limit.
    double y_low_;
    double y_high_;
};

}  // namespace csgrt
