#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/ray.h"

namespace csgrt {

/// The exact reference for triangle meshes: CGAL's AABB tree over the same (rounded) triangles
/// as a TriangleSet, queried with the Exact_predicates_inexact_constructions_kernel. Whether a
/// ray hits a triangle is decided by exact predicates (CGAL::do_intersect); the nearest hit is
/// taken among the triangles exact predicates say are hit, with t computed in long double from
/// the triangle's plane (CGAL's own first_intersection constructs points inexactly), or, for a
/// ray lying in the plane, by exact constructions (Epeck). The only
/// CGAL code in csgrt lives behind this class, so CGAL's compile cost stays in one file.
class CgalReference {
public:
    struct Answer {
        double t = 0.0;
        std::uint32_t primitive = kNoIndex;
    };

    /// Builds the tree over the corners stored in `set` (so float sets are judged on their
    /// rounded vertices, not the file's).
    template <class Real>
    explicit CgalReference(const TriangleSet<Real>& set);
    ~CgalReference();
    CgalReference(CgalReference&&) noexcept;
    CgalReference& operator=(CgalReference&&) noexcept;

    /// Exact: does the ray (t in [t_min, t_max]) touch any triangle? For t_min = 0 and
    /// t_max = inf the query is a CGAL ray; otherwise a segment between the rounded end points.
    bool do_intersect(const Ray& ray) const;
    /// Every triangle the ray touches, decided exactly, in increasing index order.
    std::vector<std::uint32_t> intersected_primitives(const Ray& ray) const;
    /// The nearest of the exactly-hit triangles; ties in t go to the lower index. A ray lying in
    /// a triangle's plane (decided exactly) meets it in a segment: its t is the segment's near
    /// end, from CGAL's exact constructions, clamped to [t_min, t_max].
    std::optional<Answer> nearest(const Ray& ray) const;
    /// CGAL's own nearest query (AABB_tree::first_intersected_primitive): the speed peer in the
    /// benchmark. Not exact: it orders hits by inexactly constructed points.
    std::optional<std::uint32_t> first_intersected_primitive(const Ray& ray) const;

    /// The distance from `point` to the nearest triangle (CGAL's AABB tree distance query,
    /// computed in double: for telling whether a point lies on the surface within a tolerance).
    double distance(const Point3& point) const;

    std::size_t size() const;
    /// Parameter t of the ray's line at the plane of triangle `primitive`, in long double.
    long double plane_t(const Ray& ray, std::uint32_t primitive) const;
    /// For a ray whose query (a CGAL ray or segment, as `do_intersect` builds it) lies in the
    /// plane of triangle `primitive` and touches it: t of the nearest point they share,
    /// constructed exactly and rounded once. Nothing when the query is not in that plane.
    std::optional<double> in_plane_t(const Ray& ray, std::uint32_t primitive) const;

private:
    struct Tree;
    std::unique_ptr<Tree> tree_;
    std::vector<std::array<Eigen::Vector3d, 3>> corners_;
};

}  // namespace csgrt
