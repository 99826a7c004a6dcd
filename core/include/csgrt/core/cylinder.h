#pragma once

#include <cstdint>

#include "csgrt/core/leaf_shape.h"
#include "csgrt/core/line_interval.h"

namespace csgrt {

/// The cylinder x^2 + z^2 = radius^2 for y in [y_min, y_max], axis along y as in Suffern, "Ray
/// Tracing from the Ground Up" (2007); place it anywhere with an Instance.
///
/// Open (capped = false): the tube surface alone, not a solid; its normal points away from the
/// axis on both faces. Capped: the closed solid bounded by the tube and the disks y = y_min
/// and y = y_max, with spans and point membership.
///
/// uv on the side: (phi / 2 pi, (y - y_min) / (y_max - y_min)) with phi = atan2(x, z) in
/// [0, 2 pi); on a cap: (phi / 2 pi, distance from the axis / radius), so u matches the side's
/// along the rim.
///
/// A ray parallel to the axis never crosses the side, not even one lying exactly in it
/// (x^2 + z^2 - radius^2 evaluates to 0): it has no single crossing point, and a hit at its
/// first point of contact would be at t_min whatever t_min is, so a ray spawned along the
/// surface would always re-hit it. The open cylinder is therefore missed, as flat shapes are
/// by rays in their plane; the capped solid is hit at its caps' rims, the ends of its span.
class Cylinder final : public detail::LeafShape<Cylinder> {
public:
    /// Which surface a hit lies on: HitRecord::primitive and Hit::primitive_id.
    enum Surface : std::uint32_t { kSide = 0, kBottomCap = 1, kTopCap = 2 };

    /// Throws InvalidParameter unless radius > 0 and finite, y_min and y_max are finite and
    /// y_min < y_max.
    Cylinder(double radius, double y_min, double y_max, bool capped);

    std::string_view kind() const override { return "cylinder"; }
    Aabb bounds() const override;
    bool is_solid() const override { return capped_; }

    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;
    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest point in [t_min, t_max] where the ray meets the surface (the solid's span
    /// ends when capped); `primitive` is the Surface.
    std::optional<Crossing> crossing(const Ray& ray) const;

    double radius() const { return radius_; }
    double y_min() const { return y_min_; }
    double y_max() const { return y_max_; }
    bool capped() const { return capped_; }

private:

    double radius_;
    double y_min_;
    double y_max_;
    bool capped_;
};

extern template class detail::LeafShape<Cylinder>;


}  // namespace csgrt
