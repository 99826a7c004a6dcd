#pragma once

#include <cstdint>

#include "csgrt/core/cylinder.h"
#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// A cone or frustum about the y axis: the circle of radius base_radius at y = 0 joined to the
/// circle of radius top_radius at y = height, so the radius at height y is
/// rho(y) = base_radius + (top_radius - base_radius) y / height. A zero radius at one end makes
/// a pointed cone with its apex there; equal radii make a cylinder. Place it anywhere with an
/// Instance.
///
/// Open (capped = false): the slanted side alone, not a solid; its normal points away from the
/// axis. Capped: the closed solid with disk caps at y = 0 and y = height (a zero-radius end has
/// no cap, just the apex). Only the nappe between the two circles is ever reported: the other
/// half of the double cone x^2 + z^2 = rho(y)^2 is cut away.
///
/// The apex is singular. A ray whose line passes through it (to within the rounding of the
/// test, about 18 ulps of the distance from the origin) hits it, even where it only touches the
/// solid there; span ends and hits within sqrt(u) of it are attributed to it. There the normal
/// is the axis direction pointing out of the tip, (0, 1, 0) for an apex on top, (0, -1, 0) for
/// one at the base: the mean of the surrounding side normals, finite and unit length.
///
/// uv on the side: (phi / 2 pi, y / height); on a cap: (phi / 2 pi, distance from the axis /
/// cap radius); at the apex: (0, y / height). A ray lying in the side (along a generator)
/// crosses nothing, as on an open Cylinder, but passes the apex of a pointed cone and so hits
/// that; the capped solid is hit where its span begins (a rim or the apex).
class Cone final : public detail::LeafShape<Cone> {
public:
    /// Which surface a hit lies on: HitRecord::primitive and Hit::primitive_id.
    enum Surface : std::uint32_t { kSide = 0, kBaseCap = 1, kTopCap = 2, kApex = 3 };

    /// Throws InvalidParameter unless both radii are >= 0 and finite, not both 0, and height is
    /// > 0 and finite.
    Cone(double base_radius, double top_radius, double height, bool capped);

    std::string_view kind() const override { return "cone"; }
    Aabb bounds() const override;
    bool is_solid() const override { return capped_; }

    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;
    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest point in [t_min, t_max] where the ray meets the surface (the solid's span
    /// ends when capped); `primitive` is the Surface.
    std::optional<Crossing> crossing(const Ray& ray) const;

    double base_radius() const { return base_radius_; }
    double top_radius() const { return top_radius_; }
    double height() const { return height_; }
    bool capped() const { return capped_; }
    /// rho(y); negative beyond an apex, on the nappe that is cut away.
    double radius_at(double y) const { return base_radius_ + slope_ * y; }
    /// True when one radius is zero; the apex is then apex().
    bool pointed() const { return pointed_; }
    const Point3& apex() const { return apex_; }

private:
    /// The line inside the solid double cone, taking our nappe's piece when the line runs
    /// through both; a piece wholly on the other nappe is left for the slab to remove.
    detail::LineInterval side_interval(const Ray& ray) const;
    bool apex_on_line(const Ray& ray, double& t) const;
    /// How far in t from the apex a hit is attributed to it.
    double apex_reach(const Ray& ray) const;
    detail::LineInterval solid_interval(const Ray& ray) const;

    double base_radius_;
    double top_radius_;
    double height_;
    bool capped_;
    double slope_;
    double normal_radial_;
    double normal_y_;
    bool pointed_;
    Point3 apex_;
    Normal3 apex_normal_;
    Point3 center_;
    double size_;
};

extern template class detail::LeafShape<Cone>;

}  // namespace csgrt
