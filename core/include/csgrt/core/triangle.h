#pragma once

#include <array>

#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// The closed triangle p0 p1 p2 in double precision. Not a solid.
///
/// Intersection is the watertight test of Woop, Benthin and Wald, "Watertight Ray/Triangle
/// Intersection", JCGT 2(1) 2013: a ray through a shared edge or vertex of a mesh hits at least
/// one of the triangles there. Conventions: edges and vertices belong to the triangle; a ray in
/// the triangle's plane grazes it and is rejected when the rounded det is 0 (always where the
/// arithmetic is exact, e.g. axis-aligned planes; otherwise rounding decides, as for any
/// grazing hit); the normal is normalize((p1 - p0) x (p2 - p0)) (counter-clockwise winding
/// faces the viewer); uv are the barycentrics (b1, b2) of p1 and p2, which the query keeps in
/// HitRecord::u/v.
class Triangle final : public detail::LeafShape<Triangle> {
public:
    /// Throws InvalidParameter unless the vertices are finite and not collinear.
    Triangle(const Point3& p0, const Point3& p1, const Point3& p2);

    std::string_view kind() const override { return "triangle"; }
    Aabb bounds() const override;

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;

    const Point3& vertex(int i) const { return vertices_[i]; }
    /// The unit normal.
    const Normal3& normal() const { return normal_; }

    /// The watertight test: where the ray meets the triangle at some t in [t_min, t_max], with
    /// the barycentrics b1, b2 of p1 and p2 as u and v.
    std::optional<Crossing> crossing(const Ray& ray) const;

private:
    std::array<Point3, 3> vertices_;
    Normal3 normal_;
};

extern template class detail::LeafShape<Triangle>;

}  // namespace csgrt
