#pragma once

#include "csgrt/core/plane.h"
#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// The closed disk of `radius` around `center` in the plane with normal `normal` (normalised).
/// Not a solid.
///
/// Conventions: the normal is the one given; the rim belongs to the disk; a ray parallel to
/// the plane never hits it; uv = (r / radius, phi / 2 pi) with r the distance from the center
/// and phi = atan2(x, z) in [0, 2 pi) measured in `frame()` (for normal +y, the y-up azimuth).
class Disk final : public detail::LeafShape<Disk> {
public:
    /// Throws InvalidParameter unless center is finite, normal finite and non-zero and radius
    /// > 0 and finite.
    Disk(const Point3& center, const Normal3& normal, double radius);

    std::string_view kind() const override { return "disk"; }
    Aabb bounds() const override;

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The point in [t_min, t_max] where the ray crosses the disk, if any.
    std::optional<Crossing> crossing(const Ray& ray) const;

    const Point3& center() const { return center_; }
    /// The unit normal.
    const Normal3& normal() const { return frame_.normal; }
    double radius() const { return radius_; }
    const SurfaceFrame& frame() const { return frame_; }

private:

    Point3 center_;
    SurfaceFrame frame_;
    double radius_;
};

extern template class detail::LeafShape<Disk>;

}  // namespace csgrt
