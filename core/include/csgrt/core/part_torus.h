#pragma once

#include "csgrt/core/torus.h"

namespace csgrt {

/// The part of a torus's surface (Torus: centred at the origin, axis +y) whose angles lie in
/// [phi_min, phi_max] around the y axis and [theta_min, theta_max] around the tube, in
/// radians and in Torus's parameterisation (phi = atan2(x, z); theta = 0 on the outer equator,
/// pi / 2 on top). An open surface, not a solid.
///
/// A range may start anywhere and cross the seam at 0 = 2 pi: [-pi/4, pi/4] around the tube is
/// the outer band; its width max - min must be in (0, 2 pi], and 2 pi keeps every angle. A ray
/// through a removed part goes on to the next crossing that is kept.
///
/// uv = ((phi - phi_min) / (phi_max - phi_min), (theta - theta_min) / (theta_max - theta_min)),
/// with the angles taken in their range: [0, 1]^2 over the part.
class PartTorus final : public Shape {
public:
    /// Throws InvalidParameter unless 0 < minor_radius < major_radius, every angle is finite and
    /// each range has a width in (0, 2 pi].
    PartTorus(double major_radius, double minor_radius, double phi_min, double phi_max,
              double theta_min, double theta_max);

    std::string_view kind() const override { return "part_torus"; }
    /// The box of the part: from the ranges of the angles' sines and cosines, padded by 32
    /// ulps of R + r.
    Aabb bounds() const override { return bounds_; }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    Hit finish(const Ray& ray, const HitRecord& record) const override;

    const Torus& torus() const { return torus_; }

    /// Whether the surface point nearest to p (off the y axis) is part of this surface.
    bool keeps(const Point3& p) const;

private:
    /// The offsets of p's angles from phi_min and theta_min, each in [0, 2 pi).
    void angle_offsets(const Point3& p, double& phi_offset, double& theta_offset) const;

    Torus torus_;
    double phi_min_;  // wrapped into [0, 2 pi)
    double phi_width_;
    double theta_min_;  // wrapped into [0, 2 pi)
    double theta_width_;
    Aabb bounds_;
};

}  // namespace csgrt
