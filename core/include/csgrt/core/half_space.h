#pragma once

#include "csgrt/core/leaf_shape.h"
#include "csgrt/core/plane.h"

namespace csgrt {

/// The solid half of space behind the plane through `point` with normal `normal`: the points p
/// with (p - point) . n < 0, the side the normal points away from (POV-Ray's plane). Its
/// surface is the plane, whose normal (the one given, normalised) points out of the solid. A
/// solid, so a CSG operand: intersected with a box it cuts the box, subtracted it keeps the
/// part in front.
///
/// Unbounded: bounds() is infinite and a span may begin at -infinity or end at +infinity (a
/// null shape at that end). Hits, uv and the treatment of parallel rays are the plane's; a ray
/// parallel to the plane is wholly inside or wholly outside, as its origin is.
class HalfSpace final : public detail::LeafShape<HalfSpace> {
public:
    /// Throws InvalidParameter unless point is finite and normal finite and non-zero.
    HalfSpace(const Point3& point, const Normal3& normal);

    std::string_view kind() const override { return "half_space"; }
    Aabb bounds() const override { return Aabb::infinite(); }
    bool is_solid() const override { return true; }

    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;
    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The point in [t_min, t_max] where the ray crosses the boundary plane, if any.
    std::optional<Crossing> crossing(const Ray& ray) const { return boundary_.crossing(ray); }

    /// The boundary plane, its normal pointing out of the solid.
    const Plane& boundary() const { return boundary_; }

private:
    Plane boundary_;
};

extern template class detail::LeafShape<HalfSpace>;

}  // namespace csgrt
