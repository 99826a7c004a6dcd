#include "csgrt/accel/closest_point.h"

#include <algorithm>
#include <array>

namespace csgrt {

Point3 closest_point_on_triangle(const Point3& p, const Point3& a, const Point3& b,
                                 const Point3& c, double& u, double& v) {
    // Ericson 2005, 5.1.5: find the Voronoi region of p among the corners, edges and face.
    const Vector3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        u = v = 0.0;
        return a;
    }
    const Vector3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3) {
        u = 1.0, v = 0.0;
        return b;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        u = d1 / (d1 - d3), v = 0.0;
        return a + u * ab;
    }
    const Vector3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6) {
        u = 0.0, v = 1.0;
        return c;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        u = 0.0, v = d2 / (d2 - d6);
        return a + v * ac;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        u = 1.0 - w, v = w;
        return b + w * (c - b);
    }
    const double sum = va + vb + vc;
    if (!(sum > 0.0) || !std::isfinite(sum)) {
        // Degenerate (zero-area) triangle that fell through every region test: its nearest
        // point lies on one of its edges.
        Point3 best = a;
        double best_d2 = (p - a).squaredNorm(), best_u = 0.0, best_v = 0.0;
        const std::array<std::array<Point3, 2>, 3> edges{{{a, b}, {a, c}, {b, c}}};
        for (int e = 0; e < 3; ++e) {
            const Vector3 edge = edges[e][1] - edges[e][0];
            const double length2 = edge.squaredNorm();
            const double s =
                length2 > 0.0 ? std::clamp((p - edges[e][0]).dot(edge) / length2, 0.0, 1.0) : 0.0;
            const Point3 q = edges[e][0] + s * edge;
            const double d2e = (p - q).squaredNorm();
            if (d2e < best_d2) {
                best = q, best_d2 = d2e;
                best_u = e == 0 ? s : (e == 2 ? 1.0 - s : 0.0);
                best_v = e == 1 ? s : (e == 2 ? s : 0.0);
            }
        }
        u = best_u, v = best_v;
        return best;
    }
    const double denominator = 1.0 / sum;
    u = vb * denominator;
    v = vc * denominator;
    return a + u * ab + v * ac;
}

namespace {

/// Triangles per leaf: a few exact point-triangle tests beat another level of boxes.
constexpr std::uint32_t kLeafSize = 4;
/// Object-median splits halve the range, so the depth is at most log2(2^32) + 1; the stack
/// holds at most one pending sibling per level.
constexpr int kMaxDepth = 64;

double squared_distance_to_box(const Point3& p, const Aabb& box) {
    const Vector3 below = (box.lower - p).cwiseMax(0.0);
    const Vector3 above = (p - box.upper).cwiseMax(0.0);
    return (below + above).squaredNorm();
}

}  // namespace

template <class Real>
ClosestPointTree<Real>::ClosestPointTree(const TriangleSet<Real>& set) : set_(&set) {
    const auto count = static_cast<std::uint32_t>(set.size());
    if (count == 0) return;
    order_.resize(count);
    std::vector<Point3> centroids(count);
    for (std::uint32_t i = 0; i < count; ++i) {
        order_[i] = i;
        centroids[i] = set.centroid(i);
    }
    nodes_.reserve(2 * (count / kLeafSize + 1));
    build(0, count, centroids, 0);
}

template <class Real>
std::uint32_t ClosestPointTree<Real>::build(std::uint32_t begin, std::uint32_t end,
                                            std::vector<Point3>& centroids, int depth) {
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    Aabb box, centroid_box;
    for (std::uint32_t i = begin; i < end; ++i) {
        box.extend(set_->bounds(order_[i]));
        centroid_box.extend(centroids[order_[i]]);
    }
    nodes_[index].box = box;
    if (end - begin <= kLeafSize || depth + 1 >= kMaxDepth) {
        nodes_[index].first = begin;
        nodes_[index].count = end - begin;
        return index;
    }
    // Split at the median centroid along the widest axis of the centroids' box; ties in the
    // coordinate are broken by index so the tree is the same on every run.
    int axis = 0;
    const Vector3 extent = centroid_box.upper - centroid_box.lower;
    if (extent.y() > extent[axis]) axis = 1;
    if (extent.z() > extent[axis]) axis = 2;
    const std::uint32_t middle = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                         const double ca = centroids[a][axis], cb = centroids[b][axis];
                         return ca < cb || (ca == cb && a < b);
                     });
    const std::uint32_t left = build(begin, middle, centroids, depth + 1);
    const std::uint32_t right = build(middle, end, centroids, depth + 1);
    nodes_[index].first = left;
    nodes_[index].second = right;
    nodes_[index].count = 0;
    return index;
}

template <class Real>
ClosestPoint ClosestPointTree<Real>::closest(const Point3& p) const {
    ClosestPoint best;
    if (nodes_.empty() || !is_finite(p)) return best;
    struct Pending {
        std::uint32_t node;
        double squared_distance;
    };
    std::array<Pending, kMaxDepth + 1> stack;
    int top = 0;
    stack[top++] = {0, squared_distance_to_box(p, nodes_[0].box)};
    while (top > 0) {
        const Pending pending = stack[--top];
        // Equal distances are still visited: a farther-indexed subtree may hold a tie that the
        // lower-index rule prefers.
        if (pending.squared_distance > best.squared_distance) continue;
        const Node& node = nodes_[pending.node];
        if (node.count > 0) {
            for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                const std::uint32_t i = order_[k];
                double u, v;
                const Point3 q = closest_point_on_triangle(
                    p, set_->corner(i, 0).template cast<double>(),
                    set_->corner(i, 1).template cast<double>(),
                    set_->corner(i, 2).template cast<double>(), u, v);
                const double d2 = (p - q).squaredNorm();
                if (d2 < best.squared_distance ||
                    (d2 == best.squared_distance && i < best.primitive)) {
                    best.point = q;
                    best.squared_distance = d2;
                    best.primitive = i;
                    best.u = u;
                    best.v = v;
                }
            }
            continue;
        }
        const double near_d2 = squared_distance_to_box(p, nodes_[node.first].box);
        const double far_d2 = squared_distance_to_box(p, nodes_[node.second].box);
        // Push the farther child first so the nearer one is searched first and tightens the
        // bound that prunes the other.
        if (near_d2 <= far_d2) {
            stack[top++] = {node.second, far_d2};
            stack[top++] = {node.first, near_d2};
        } else {
            stack[top++] = {node.first, near_d2};
            stack[top++] = {node.second, far_d2};
        }
    }
    return best;
}

template <class Real>
std::size_t ClosestPointTree<Real>::bytes() const {
    return nodes_.capacity() * sizeof(Node) + order_.capacity() * sizeof(std::uint32_t);
}

template class ClosestPointTree<float>;
template class ClosestPointTree<double>;

}  // namespace csgrt
