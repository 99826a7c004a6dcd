#pragma once

#include "csgrt/core/leaf_shape.h"

namespace csgrt {

/// The closed, axis-aligned solid box [lower, upper].
///
/// Faces are numbered 0..5 = -x, +x, -y, +y, -z, +z (2 axis + 1 for the upper side); a hit's
/// `primitive` is its face, and the normal is that face's outward axis. uv on a face are the
/// other two coordinates in cyclic order (x: (y, z); y: (z, x); z: (x, y)), scaled to [0, 1].
///
/// The box is closed, and every query treats it as the set of points it contains: a ray that
/// lies in a face plane and crosses the face, or touches only an edge or a corner, hits it
/// (a zero-length span for a single point). Where the ray enters through an edge or corner,
/// the face of the lowest axis is reported.
class Box final : public detail::LeafShape<Box> {
public:
    /// Throws InvalidParameter unless lower and upper are finite and lower < upper on every
    /// axis.
    Box(const Point3& lower, const Point3& upper);

    std::string_view kind() const override { return "box"; }
    Aabb bounds() const override { return Aabb(lower_, upper_); }
    bool is_solid() const override { return true; }

    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    /// Closed: points on the faces are inside.
    bool contains(const Point3& p) const override;
    /// Where the hit of a record `crossing` made lies, its normal and uv (LeafShape::finish).
    SurfacePoint surface_at(const Ray& ray, const HitRecord& record) const;
    /// The nearest point in [t_min, t_max] where the ray meets the box (from inside: where it
    /// leaves); `primitive` is the face.
    std::optional<Crossing> crossing(const Ray& ray) const;

    const Point3& lower() const { return lower_; }
    const Point3& upper() const { return upper_; }

    /// The interval [t_enter, t_exit] of the ray's whole line inside the box, and the faces it
    /// enters and leaves through; false when the line misses the box.
    bool line_interval(const Ray& ray, double& t_enter, double& t_exit, int& enter_face,
                       int& exit_face) const;

private:
    Point3 lower_;
    Point3 upper_;
};

extern template class detail::LeafShape<Box>;

}  // namespace csgrt
