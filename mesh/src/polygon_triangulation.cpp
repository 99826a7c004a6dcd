// Polygon faces into triangles: ear clipping in the plane of the polygon's Newell normal.

#include "polygon_triangulation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace csgrt::detail {

namespace {

/// Ear clipping over a doubly linked ring of a polygon's corners (Eberly, "Triangulation by
/// Ear Clipping", 2002; the ring filtering and local cures follow Mapbox's earcut, Agafonkin,
/// https://github.com/mapbox/earcut, 2016). A corner that blocks an ear must be reflex or
/// collinear and lie in it; a corner at the same place as the ear's first corner does not block
/// it, so a keyhole polygon (the outer loop, a bridge, the hole and the bridge back, with the
/// bridge's corners repeated) is clipped around its hole. Points are 2D, counter-clockwise.
///
/// The corners still in the ring are found by a static kd-tree (built once, O(n log n)) whose
/// nodes count the corners left under them: an ear test descends only into nodes that hold
/// corners and whose box is not wholly outside the ear, so a long thin ear (a fan across a
/// comb's base or along a side of collinear corners, the ears such polygons force) visits the
/// few cells along its edges instead of every corner in its bounding box, which earcut's
/// z-order scan visited. With the walk resuming at the corner before each ear (below), such
/// polygons of 10^5 corners take milliseconds; they took 17 s (docs/accuracy.md).
class EarClipper {
public:
    EarClipper(const std::vector<Eigen::Vector2d>& points,
               std::vector<std::array<std::uint32_t, 3>>& out)
        : points_(points), out_(out), nodes_(points.size()) {
        const std::size_t n = points.size();
        for (std::size_t i = 0; i < n; ++i) {
            Node& node = nodes_[i];
            node.prev = static_cast<int>((i + n - 1) % n);
            node.next = static_cast<int>((i + 1) % n);
        }
        build_tree();
    }

    /// Clips the ring; returns the corners left when no ear and no local fix remains (empty
    /// when the whole polygon was triangulated).
    std::vector<std::uint32_t> run() {
        std::vector<std::uint32_t> left;
        int ear = 0;
        int stop = ear;
        int pass = 0;
        while (nodes_[ear].prev != nodes_[ear].next) {
            const int prev = nodes_[ear].prev, next = nodes_[ear].next;
            if (is_ear(ear)) {
                emit(prev, ear, next);
                remove(ear);
                // The corner before the ear has a new neighbour, so it may have become an ear:
                // look there first. Earcut moves on past the next corner, which leaves such
                // corners for the next round; on a side of collinear corners (no ear but at
                // the ends) every round then walked the whole ring for one ear.
                ear = prev;
                stop = ear;
                continue;
            }
            ear = next;
            if (ear != stop) continue;
            // A whole round without an ear: drop repeated and collinear corners, then cut off
            // locally self-intersecting pieces (earcut's passes 1 and 2); then give up.
            if (pass == 0) {
                ear = filter(ear);
            } else if (pass == 1) {
                ear = filter(cure_local_intersections(filter(ear)));
            } else {
                int p = ear;
                do {
                    left.push_back(static_cast<std::uint32_t>(p));
                    p = nodes_[p].next;
                } while (p != ear);
                break;
            }
            ++pass;
            stop = ear;
            if (ear < 0) break;
        }
        return left;
    }

private:
    struct Node {
        int prev = -1, next = -1;
    };

    /// A kd-tree node over order_[begin, end): the box of its corners and how many of them are
    /// still in the ring. Children of node k are 2k + 1 and 2k + 2, splitting at the middle.
    struct Cell {
        Eigen::Vector2d lower, upper;
        std::uint32_t begin = 0, end = 0;
        std::uint32_t left = 0;
    };
    static constexpr std::size_t kLeafSize = 8;

    /// Twice the signed area of (a, b, c): positive when counter-clockwise.
    double cross(int a, int b, int c) const {
        const Eigen::Vector2d &pa = points_[a], &pb = points_[b], &pc = points_[c];
        return (pb.x() - pa.x()) * (pc.y() - pa.y()) - (pb.y() - pa.y()) * (pc.x() - pa.x());
    }
    static double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        const Eigen::Vector2d& c) {
        return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    }
    bool same_place(int a, int b) const { return points_[a] == points_[b]; }

    void build_tree() {
        const std::size_t n = points_.size();
        order_.resize(n);
        for (std::size_t i = 0; i < n; ++i) order_[i] = static_cast<int>(i);
        std::size_t cells = 1;
        while (cells * kLeafSize < n) cells *= 2;
        cells_.resize(2 * cells - 1);
        leaf_of_.resize(n);
        // Explicit stack: (cell, begin, end).
        struct Task {
            std::size_t cell, begin, end;
        };
        std::vector<Task> tasks{{0, 0, n}};
        while (!tasks.empty()) {
            const Task task = tasks.back();
            tasks.pop_back();
            Cell& cell = cells_[task.cell];
            cell.lower = cell.upper = points_[order_[task.begin]];
            for (std::size_t k = task.begin; k < task.end; ++k) {
                cell.lower = cell.lower.cwiseMin(points_[order_[k]]);
                cell.upper = cell.upper.cwiseMax(points_[order_[k]]);
            }
            cell.begin = static_cast<std::uint32_t>(task.begin);
            cell.end = static_cast<std::uint32_t>(task.end);
            cell.left = cell.end - cell.begin;
            const std::size_t first_child = 2 * task.cell + 1;
            if (first_child >= cells_.size() || task.end - task.begin <= 1) {
                for (std::size_t k = task.begin; k < task.end; ++k) leaf_of_[order_[k]] = task.cell;
                continue;
            }
            // Split the longer side at the median.
            const int axis = (cell.upper - cell.lower).x() >= (cell.upper - cell.lower).y() ? 0 : 1;
            const std::size_t middle = task.begin + (task.end - task.begin) / 2;
            std::nth_element(order_.begin() + static_cast<std::ptrdiff_t>(task.begin),
                             order_.begin() + static_cast<std::ptrdiff_t>(middle),
                             order_.begin() + static_cast<std::ptrdiff_t>(task.end),
                             [&](int a, int b) { return points_[a][axis] < points_[b][axis]; });
            tasks.push_back({first_child, task.begin, middle});
            tasks.push_back({first_child + 1, middle, task.end});
        }
    }

    void emit(int a, int b, int c) {
        out_.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                        static_cast<std::uint32_t>(c)});
    }

    void remove(int p) {
        Node& node = nodes_[p];
        nodes_[node.next].prev = node.prev;
        nodes_[node.prev].next = node.next;
        in_ring_[p] = false;
        for (std::size_t cell = leaf_of_[p];; cell = (cell - 1) / 2) {
            --cells_[cell].left;
            if (cell == 0) break;
        }
    }
    /// Whether corner p, a reflex or collinear corner, lies in the closed ear (a, b, c) and is
    /// not a repetition of a (a keyhole's bridge end).
    bool blocks(int p, int a, int b, int c) const {
        if (p == a || p == b || p == c || same_place(p, a)) return false;
        if (!(cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0))
            return false;
        return cross(nodes_[p].prev, p, nodes_[p].next) <= 0.0;
    }

    /// Whether the box lies wholly on the outer side of the directed edge (from, to) of a
    /// counter-clockwise triangle: then no point of it is in the triangle.
    static bool outside(const Cell& cell, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
        for (const Eigen::Vector2d& corner :
             {cell.lower, cell.upper, Eigen::Vector2d(cell.lower.x(), cell.upper.y()),
              Eigen::Vector2d(cell.upper.x(), cell.lower.y())}) {
            if (!(cross(from, to, corner) < 0.0)) return false;
        }
        return true;
    }

    bool is_ear(int b) {
        const int a = nodes_[b].prev, c = nodes_[b].next;
        if (!(cross(a, b, c) > 0.0)) return false;  // reflex or collinear: not an ear
        const Eigen::Vector2d &pa = points_[a], &pb = points_[b], &pc = points_[c];
        const Eigen::Vector2d lower = pa.cwiseMin(pb).cwiseMin(pc);
        const Eigen::Vector2d upper = pa.cwiseMax(pb).cwiseMax(pc);
        // Cells that hold corners of the ring and may meet the closed ear.
        pending_.assign(1, 0);
        while (!pending_.empty()) {
            const std::size_t index = pending_.back();
            pending_.pop_back();
            const Cell& cell = cells_[index];
            if (cell.left == 0 || (cell.lower.array() > upper.array()).any() ||
                (cell.upper.array() < lower.array()).any() || outside(cell, pa, pb) ||
                outside(cell, pb, pc) || outside(cell, pc, pa)) {
                continue;
            }
            const std::size_t first_child = 2 * index + 1;
            if (first_child < cells_.size() && cell.end - cell.begin > 1) {
                pending_.push_back(first_child);
                pending_.push_back(first_child + 1);
                continue;
            }
            for (std::uint32_t k = cell.begin; k < cell.end; ++k) {
                const int p = order_[k];
                if (in_ring_[p] && blocks(p, a, b, c)) return false;
            }
        }
        return true;
    }

    /// Removes corners that repeat their successor's place or are collinear with their
    /// neighbours, starting at `start`; returns a corner still in the ring (-1: fewer than 3).
    int filter(int start) {
        if (start < 0) return start;
        int end = start, p = start;
        bool again;
        do {
            again = false;
            const int next = nodes_[p].next;
            if (same_place(p, next) || cross(nodes_[p].prev, p, next) == 0.0) {
                remove(p);
                p = end = nodes_[p].prev;
                if (p == nodes_[p].next || nodes_[p].prev == nodes_[p].next) return -1;
                again = true;
            } else {
                p = next;
            }
        } while (again || p != end);
        return end;
    }

    bool locally_inside(int a, int b) const {
        const int prev = nodes_[a].prev, next = nodes_[a].next;
        return cross(prev, a, next) > 0.0 ? cross(a, b, next) <= 0.0 && cross(a, prev, b) <= 0.0
                                          : cross(a, b, prev) > 0.0 || cross(a, next, b) > 0.0;
    }

    bool segments_cross(int p1, int q1, int p2, int q2) const {
        auto sign = [](double v) { return (v > 0.0) - (v < 0.0); };
        auto on_segment = [&](int p, int q, int r) {
            const Eigen::Vector2d &a = points_[p], &b = points_[q], &c = points_[r];
            return b.x() <= std::max(a.x(), c.x()) && b.x() >= std::min(a.x(), c.x()) &&
                   b.y() <= std::max(a.y(), c.y()) && b.y() >= std::min(a.y(), c.y());
        };
        const int o1 = sign(cross(p1, q1, p2)), o2 = sign(cross(p1, q1, q2));
        const int o3 = sign(cross(p2, q2, p1)), o4 = sign(cross(p2, q2, q1));
        if (o1 != o2 && o3 != o4) return true;
        return (o1 == 0 && on_segment(p1, p2, q1)) || (o2 == 0 && on_segment(p1, q2, q1)) ||
               (o3 == 0 && on_segment(p2, p1, q2)) || (o4 == 0 && on_segment(p2, q1, q2));
    }

    /// Where the ring crosses itself over one corner (a, p, p.next, b with ap crossing
    /// p.next b), cuts off the triangle (a, p, b).
    int cure_local_intersections(int start) {
        if (start < 0) return start;
        int p = start;
        do {
            const int a = nodes_[p].prev, b = nodes_[nodes_[p].next].next;
            if (!same_place(a, b) && segments_cross(a, p, nodes_[p].next, b) &&
                locally_inside(a, b) && locally_inside(b, a)) {
                emit(a, p, b);
                cut_crossings_ = true;
                remove(nodes_[p].next);
                remove(p);
                p = start = b;
            }
            p = nodes_[p].next;
        } while (p != start && nodes_[p].prev != nodes_[p].next);
        return p;
    }

public:
    /// Whether a self-crossing of the ring was cut off (the polygon was not simple).
    bool cut_crossings() const { return cut_crossings_; }

private:
    const std::vector<Eigen::Vector2d>& points_;
    std::vector<std::array<std::uint32_t, 3>>& out_;
    bool cut_crossings_ = false;
    std::vector<Node> nodes_;
    std::vector<char> in_ring_ = std::vector<char>(nodes_.size(), 1);
    std::vector<int> order_;
    std::vector<Cell> cells_;
    std::vector<std::size_t> leaf_of_;
    std::vector<std::size_t> pending_;
};

}  // namespace

bool triangulate(std::span<const std::uint32_t> polygon,
                 const std::vector<Eigen::Vector3d>& vertices,
                 std::vector<std::array<std::uint32_t, 3>>& triangles) {
    const std::size_t n = polygon.size();
    if (n == 3) {
        triangles.push_back({polygon[0], polygon[1], polygon[2]});
        return true;
    }
    auto fan = [&](std::span<const std::uint32_t> corners) {
        for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
            triangles.push_back({corners[0], corners[k], corners[k + 1]});
        }
    };
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d& a = vertices[polygon[i]];
        const Eigen::Vector3d& b = vertices[polygon[(i + 1) % n]];
        normal +=
            Eigen::Vector3d((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                            (a.x() - b.x()) * (a.y() + b.y()));
    }
    if (!(normal.squaredNorm() > 0.0)) {
        fan(polygon);
        return false;
    }
    // Project along the dominant normal axis; (x, y, axis) is a cyclic order, so the projected
    // polygon is counter-clockwise exactly when normal[axis] > 0. Mirror it otherwise.
    int axis;
    normal.cwiseAbs().maxCoeff(&axis);
    const int x = (axis + 1) % 3, y = (axis + 2) % 3;
    const double mirror = normal[axis] > 0.0 ? 1.0 : -1.0;
    std::vector<Eigen::Vector2d> points(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d& p = vertices[polygon[i]];
        points[i] = Eigen::Vector2d(p[x], mirror * p[y]);
    }
    std::vector<std::array<std::uint32_t, 3>> corners;
    corners.reserve(n - 2);
    EarClipper clipper(points, corners);
    const std::vector<std::uint32_t> left = clipper.run();
    for (const auto& t : corners)
        triangles.push_back({polygon[t[0]], polygon[t[1]], polygon[t[2]]});
    if (left.size() < 3) return !clipper.cut_crossings();
    std::vector<std::uint32_t> rest;
    for (std::uint32_t i : left) rest.push_back(polygon[i]);
    fan(rest);
    return false;
}

}  // namespace csgrt::detail
