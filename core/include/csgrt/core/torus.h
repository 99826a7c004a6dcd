#pragma once

#include <string_view>

#include "csgrt/core/leaf_shape.h"
#include "csgrt/core/sphere.h"

namespace csgrt {

/// The solid ring torus centred at the origin with axis +y: the points within minor_radius r
/// of the circle of radius major_radius R in the plane y = 0. Its surface is
/// (x^2 + y^2 + z^2 + R^2 - r^2)^2 = 4 R^2 (x^2 + z^2); place it anywhere with an Instance.
///
/// Only ring tori (r < R) are accepted: for r >= R (horn and spindle tori) the quartic also
/// describes an inner surface that bounds nothing, and the surface has singular points on the
/// axis where no normal exists.
///
/// Parameterisation: phi = atan2(x, z) in [0, 2 pi) around the y axis; theta in [0, 2 pi)
/// around the tube, from the outer equator (theta = 0) over the top (pi / 2) to the inner
/// equator (pi): a surface point is ((R + r cos theta) sin phi, r sin theta, (R + r cos theta)
/// cos phi). uv = (phi / 2 pi, theta / 2 pi).
///
/// Intersection (docs/accuracy.md): the ray is clipped to a bounding sphere and slab; the
/// quartic is built around the middle of that chord, so its coefficients stay of the torus's
/// size however far away the origin is; solve_quartic brackets every root and reports each
/// near-tangency as a double root, which is then decided by the well-conditioned tube function
/// (rho - R)^2 + y^2 - r^2 along the original ray; every other root is polished on that same
/// function in the original parameterisation, inside a bracket whose signs are verified.
class Torus final : public detail::LeafShape<Torus> {
public:
    /// Throws InvalidParameter unless 0 < minor_radius < major_radius, both finite.
    Torus(double major_radius, double minor_radius);

    std::string_view kind() const override { return "torus"; }
    Aabb bounds() const override;
    bool is_solid() const override { return true; }

    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;
    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest root of the ray's line with the torus in [t_min, t_max], if any.
    std::optional<Crossing> crossing(const Ray& ray) const;

    double major_radius() const { return major_radius_; }
    double minor_radius() const { return minor_radius_; }

    /// Where the ray's line crosses the surface, in increasing t: 0, 2 or 4 values, a tangency
    /// reported twice, so that they pair up as (enter, exit). All of them whenever the line's
    /// piece inside the bounds meets [t_min, t_max]; none otherwise.
    int line_roots(const Ray& ray, double roots[4]) const;

    /// The angles (phi around the y axis, theta around the tube, both in [0, 2 pi)) of the
    /// surface point nearest to p (p off the y axis).
    void surface_angles(const Point3& p, double& phi, double& theta) const;

    /// Throws InvalidParameter, naming `what`, unless 0 < minor < major, both finite.
    static void require_ring_radii(double major_radius, double minor_radius, std::string_view what);

private:
    double major_radius_;
    double minor_radius_;
    /// Encloses the torus with a margin, so the quartic is clearly positive where it is cut.
    Sphere bounding_sphere_;
};

extern template class detail::LeafShape<Torus>;

}  // namespace csgrt
