#pragma once

#include "csgrt/core/leaf_shape.h"
#include "csgrt/core/surface_frame.h"

namespace csgrt {

/// The infinite plane through `point` with normal `normal` (normalised). Not a solid.
///
/// Conventions: the normal is the one given (not turned toward the ray); a ray parallel to the
/// plane never hits it, even one lying in it; uv are the hit's coordinates along x_axis and
/// z_axis of `frame()`, measured from `point`, wrapped into [0, 1) (one texture tile per unit).
class Plane final : public detail::LeafShape<Plane> {
public:
    /// Throws InvalidParameter unless point is finite and normal finite and non-zero.
    Plane(const Point3& point, const Normal3& normal);

    std::string_view kind() const override { return "plane"; }
    Aabb bounds() const override { return Aabb::infinite(); }

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The point in [t_min, t_max] where the ray crosses the plane, if any.
    std::optional<Crossing> crossing(const Ray& ray) const;

    const Point3& point() const { return point_; }
    /// The unit normal.
    const Normal3& normal() const { return frame_.normal; }
    const SurfaceFrame& frame() const { return frame_; }

private:

    Point3 point_;
    SurfaceFrame frame_;
};

extern template class detail::LeafShape<Plane>;

}  // namespace csgrt
