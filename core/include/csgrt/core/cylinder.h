#pragma once

#include <cstdint>

#include "csgrt/core/shape.h"

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
class Cylinder final : public Shape {
public:
    /// Which surface a hit lies on: HitRecord::primitive and Hit::primitive_id.
    enum Surface : std::uint32_t { kSide = 0, kBottomCap = 1, kTopCap = 2 };

    /// Throws InvalidParameter unless radius > 0 and finite, y_min and y_max are finite and
    /// y_min < y_max.
    Cylinder(double radius, double y_min, double y_max, bool capped);

    std::string_view kind() const override { return "cylinder"; }
    Aabb bounds() const override;
    bool is_solid() const override { return capped_; }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;
    Hit finish(const Ray& ray, const HitRecord& record) const override;

    double radius() const { return radius_; }
    double y_min() const { return y_min_; }
    double y_max() const { return y_max_; }
    bool capped() const { return capped_; }

private:
    bool nearest(const Ray& ray, double& t, std::uint32_t& surface) const;

    double radius_;
    double y_min_;
    double y_max_;
    bool capped_;
};

namespace detail {

/// The closed part [t0, t1] of a ray's line inside a solid, with the surface each end lies on.
/// Either end may be infinite (not a crossing); an empty interval has t0 > t1.
struct LineInterval {
    double t0 = kInfinity;
    double t1 = -kInfinity;
    std::uint32_t surface0 = 0;
    std::uint32_t surface1 = 0;

    bool empty() const { return !(t0 <= t1); }
};

/// The ray's line inside the infinite solid cylinder x^2 + z^2 <= radius^2 (object space, any
/// direction length); both ends are labelled `side`. Uses the cancellation-free quadratic after
/// moving a far origin to the line's closest approach to the axis, so t keeps a relative error
/// of a few ulps for origins millions of radii away.
LineInterval infinite_cylinder_interval(const Ray& ray, double radius, std::uint32_t side);

/// The ray's line between the planes y = lower and y = upper (lower <= upper), each end
/// labelled with its plane's surface. A ray parallel to the planes is inside everywhere (the
/// closed slab) or nowhere.
LineInterval slab_interval(const Ray& ray, double lower, double upper, std::uint32_t lower_surface,
                           std::uint32_t upper_surface);

/// The overlap of two intervals: the later entry and the earlier exit, each with its surface;
/// ties keep `a`'s surface.
LineInterval overlap(const LineInterval& a, const LineInterval& b);

/// The nearest point in [t_min, t_max] where the ray crosses the side of an open surface of
/// revolution limited to `slab`: a finite end of `side` inside the slab, with its label.
bool nearest_open_surface_hit(const Ray& ray, const LineInterval& side, const LineInterval& slab,
                              double& t, std::uint32_t& surface);

}  // namespace detail

}  // namespace csgrt
