#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/math.h"

namespace csgrt {

/// The point of a triangle set nearest to a query point.
struct ClosestPoint {
    /// The nearest point on the surface (NaN for an empty set or an invalid query point).
    Point3 point = Point3::Constant(std::numeric_limits<double>::quiet_NaN());
    /// Its squared distance to the query point (+infinity when there is no answer).
    double squared_distance = kInfinity;
    /// The triangle it lies on (kNoIndex when there is no answer).
    std::uint32_t primitive = kNoIndex;
    /// Barycentric weights of corners 1 and 2 of that triangle at the point.
    double u = 0.0;
    double v = 0.0;
};

/// The point of triangle (a, b, c) nearest to p, in double, with the barycentric weights of b
/// and c there: Ericson, "Real-Time Collision Detection", 2005, section 5.1.5 (the Voronoi
/// regions of the corners and edges are tested first, the face last). A degenerate triangle
/// gives the nearest point of its edges.
Point3 closest_point_on_triangle(const Point3& p, const Point3& a, const Point3& b,
                                 const Point3& c, double& u, double& v);

/// A bounding-volume hierarchy over a TriangleSet for point queries: the nearest surface point,
/// so unsigned distances (and, with a containment test, signed ones). Kept apart from the ray
/// structures: a point query orders children by box distance, not by a ray's entry, and a
/// binary tree of object-median splits is all it needs (CGAL's AABB_tree::closest_point does
/// the same). Built once in the constructor; queries are const, thread-safe and allocate
/// nothing. The set must outlive the tree.
template <class Real>
class ClosestPointTree {
public:
    /// Builds over every triangle of `set` (an empty set gives a tree that answers nothing).
    explicit ClosestPointTree(const TriangleSet<Real>& set);

    /// The nearest point of the set to p. Ties in distance go to the lower triangle index, so
    /// the answer does not depend on the tree's shape. No answer for a non-finite p.
    ClosestPoint closest(const Point3& p) const;

    std::size_t size() const { return set_->size(); }
    std::size_t bytes() const;

private:
    /// A node's box, and either two children (count == 0: `first` and `second`) or a leaf's
    /// range [first, first + count) of `order_`.
    struct Node {
        Aabb box;
        std::uint32_t first = 0;
        std::uint32_t second = 0;
        std::uint32_t count = 0;
    };
    std::uint32_t build(std::uint32_t begin, std::uint32_t end, std::vector<Point3>& centroids,
                        int depth);

    const TriangleSet<Real>* set_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> order_;
};

extern template class ClosestPointTree<float>;
extern template class ClosestPointTree<double>;

}  // namespace csgrt
