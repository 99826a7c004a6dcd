// Polygon faces into triangles: ear clipping in the plane of the polygon's Newell normal.

#include "polygon_triangulation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace csgrt::detail {

namespace {

/// Ear clipping over a doubly linked ring of a polygon's corners, with the ear test limited to
/// the corners near the ear by a z-order (Morton) index, after Mapbox's earcut (Agafonkin,
/// https://github.com/mapbox/earcut, 2016; Eberly, "Triangulation by Ear Clipping", 2002 for
/// the method). A corner that blocks an ear must be reflex and inside it; a corner at the same
/// place as the ear's first corner does not block it, so a keyhole polygon (the outer loop, a
/// bridge, the hole and the bridge back, with the bridge's corners repeated) is clipped around
/// its hole. The corners looked at per ear are those whose Morton codes lie within the ear's
/// box, so polygons of 10^5 corners take milliseconds instead of the minutes of the quadratic
/// scan. Points are 2D, counter-clockwise.
class EarClipper {
public:
    EarClipper(const std::vector<Eigen::Vector2d>& points,
               std::vector<std::array<std::uint32_t, 3>>& out)
        : points_(points), out_(out), nodes_(points.size()) {
        const std::size_t n = points.size();
        Eigen::Vector2d lower = points[0], upper = points[0];
        for (const Eigen::Vector2d& p : points) {
            lower = lower.cwiseMin(p);
            upper = upper.cwiseMax(p);
        }
        lower_ = lower;
        const double size = (upper - lower).maxCoeff();
        inverse_size_ = size > 0.0 && std::isfinite(size) ? 32767.0 / size : 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            Node& node = nodes_[i];
            node.prev = static_cast<int>((i + n - 1) % n);
            node.next = static_cast<int>((i + 1) % n);
            node.z = morton(points[i]);
        }
        // The z-order list: every corner sorted by Morton code.
        std::vector<int> order(n);
        for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<int>(i);
        std::sort(order.begin(), order.end(),
                  [&](int a, int b) { return nodes_[a].z < nodes_[b].z; });
        for (std::size_t k = 0; k < n; ++k) {
            nodes_[order[k]].prev_z = k > 0 ? order[k - 1] : -1;
            nodes_[order[k]].next_z = k + 1 < n ? order[k + 1] : -1;
        }
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
                ear = nodes_[next].next;
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
        int prev = -1, next = -1, prev_z = -1, next_z = -1;
        std::uint32_t z = 0;
    };

    /// Twice the signed area of (a, b, c): positive when counter-clockwise.
    double cross(int a, int b, int c) const {
        const Eigen::Vector2d &pa = points_[a], &pb = points_[b], &pc = points_[c];
        return (pb.x() - pa.x()) * (pc.y() - pa.y()) - (pb.y() - pa.y()) * (pc.x() - pa.x());
    }
    bool same_place(int a, int b) const { return points_[a] == points_[b]; }

    std::uint32_t morton(const Eigen::Vector2d& p) const {
        auto spread = [](std::uint32_t v) {
            v = (v | (v << 8)) & 0x00FF00FFu;
            v = (v | (v << 4)) & 0x0F0F0F0Fu;
            v = (v | (v << 2)) & 0x33333333u;
            v = (v | (v << 1)) & 0x55555555u;
            return v;
        };
        const auto x = static_cast<std::uint32_t>((p.x() - lower_.x()) * inverse_size_);
        const auto y = static_cast<std::uint32_t>((p.y() - lower_.y()) * inverse_size_);
        return spread(x) | (spread(y) << 1);
    }

    void emit(int a, int b, int c) {
        out_.push_back({static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
                        static_cast<std::uint32_t>(c)});
    }

    void remove(int p) {
        Node& node = nodes_[p];
        nodes_[node.next].prev = node.prev;
        nodes_[node.prev].next = node.next;
        if (node.prev_z >= 0) nodes_[node.prev_z].next_z = node.next_z;
        if (node.next_z >= 0) nodes_[node.next_z].prev_z = node.prev_z;
    }

    /// Whether corner p, a reflex or collinear corner, lies in the closed ear (a, b, c) and is
    /// not a repetition of a (a keyhole's bridge end).
    bool blocks(int p, int a, int b, int c) const {
        if (p == a || p == b || p == c || same_place(p, a)) return false;
        if (!(cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0))
            return false;
        return cross(nodes_[p].prev, p, nodes_[p].next) <= 0.0;
    }

    bool is_ear(int b) const {
        const int a = nodes_[b].prev, c = nodes_[b].next;
        if (!(cross(a, b, c) > 0.0)) return false;  // reflex or collinear: not an ear
        const Eigen::Vector2d lower = points_[a].cwiseMin(points_[b]).cwiseMin(points_[c]);
        const Eigen::Vector2d upper = points_[a].cwiseMax(points_[b]).cwiseMax(points_[c]);
        const std::uint32_t z_min = morton(lower), z_max = morton(upper);
        auto in_box = [&](int p) {
            const Eigen::Vector2d& q = points_[p];
            return q.x() >= lower.x() && q.x() <= upper.x() && q.y() >= lower.y() &&
                   q.y() <= upper.y();
        };
        // Every corner in the box has a Morton code in [z_min, z_max]: walk both ways from
        // the ear's own code.
        for (int p = nodes_[b].prev_z; p >= 0 && nodes_[p].z >= z_min; p = nodes_[p].prev_z) {
            if (in_box(p) && blocks(p, a, b, c)) return false;
        }
        for (int p = nodes_[b].next_z; p >= 0 && nodes_[p].z <= z_max; p = nodes_[p].next_z) {
            if (in_box(p) && blocks(p, a, b, c)) return false;
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
    Eigen::Vector2d lower_;
    double inverse_size_ = 0.0;
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
