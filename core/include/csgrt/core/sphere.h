#pragma once

#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// The solid ball |p - center| <= radius.
///
/// Parameterisation (as in Suffern, "Ray Tracing from the Ground Up", with y up): azimuth
/// phi = atan2(x, z) in [0, 2 pi), polar angle theta = acos(y / r) in [0, pi] from +y;
/// uv = (phi / 2 pi, 1 - theta / pi).
class Sphere final : public detail::LeafShape<Sphere> {
public:
    /// Throws InvalidParameter unless center is finite and radius > 0 and finite.
    Sphere(const Point3& center, double radius);

    std::string_view kind() const override { return "sphere"; }
    Aabb bounds() const override;
    bool is_solid() const override { return true; }

    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;
    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest root of the ray's line with the sphere in [t_min, t_max], if any.
    std::optional<Crossing> crossing(const Ray& ray) const;

    const Point3& center() const { return center_; }
    double radius() const { return radius_; }

    /// Both roots t0 <= t1 of the ray's line with the sphere, or false when it misses. Any
    /// radius and direction length a double holds: extreme ones are rescaled by powers of two.
    bool line_roots(const Ray& ray, double& t0, double& t1) const;
    /// The unit vector along `offset` (a point minus the center), computed without underflow
    /// or overflow for offsets of the sphere's size, however tiny or huge that is.
    Normal3 unit_along(const Vector3& offset) const { return (offset * scale_).normalized(); }

private:
    Point3 center_;
    double radius_;
    /// 2^-e with radius * scale in [1, 2): exact rescaling to a unit-sized sphere.
    double scale_;
    int exponent_;
    /// Whether the radius is in [2^-200, 2^200], where its square and products with squared
    /// direction lengths in [2^-400, 2^400] stay normal doubles (the fast path of line_roots).
    bool moderate_;
};

extern template class detail::LeafShape<Sphere>;

}  // namespace csgrt
