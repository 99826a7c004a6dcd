#pragma once

#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// The closed parallelogram corner + s edge_a + t edge_b, s and t in [0, 1] (a rectangle when
/// the edges are perpendicular). Not a solid.
///
/// Conventions: edges and corners belong to it; a ray parallel to its plane never hits it; the
/// normal is normalize(edge_a x edge_b); uv = (s, t), which the query keeps in HitRecord::u/v.
class Rectangle final : public detail::LeafShape<Rectangle> {
public:
    /// Throws InvalidParameter unless corner and edges are finite, the edges non-zero and not
    /// parallel.
    Rectangle(const Point3& corner, const Vector3& edge_a, const Vector3& edge_b);

    std::string_view kind() const override { return "rectangle"; }
    Aabb bounds() const override;

    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;

    const Point3& corner() const { return corner_; }
    const Vector3& edge_a() const { return edge_a_; }
    const Vector3& edge_b() const { return edge_b_; }
    /// The unit normal.
    const Normal3& normal() const { return normal_; }

    /// Where the ray meets the parallelogram at some t in [t_min, t_max], with the hit's
    /// parameters (s, t) as u and v.
    std::optional<Crossing> crossing(const Ray& ray) const;

private:
    Point3 corner_;
    Vector3 edge_a_;
    Vector3 edge_b_;
    Normal3 normal_;
    // Dual vectors: for q = s edge_a + r edge_b (+ any multiple of the normal), s = q . dual_a_
    // and r = q . dual_b_.
    Vector3 dual_a_;
    Vector3 dual_b_;
};

extern template class detail::LeafShape<Rectangle>;

}  // namespace csgrt
