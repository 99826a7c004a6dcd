#pragma once

#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"

namespace csgrt {

/// An axis-aligned box [lower, upper]. A default box is empty (lower = +inf, upper = -inf), so
/// extending it by anything yields that thing's box.
struct Aabb {
    Point3 lower{kInfinity, kInfinity, kInfinity};
    Point3 upper{-kInfinity, -kInfinity, -kInfinity};

    Aabb() = default;
    Aabb(const Point3& a, const Point3& b) : lower(a.cwiseMin(b)), upper(a.cwiseMax(b)) {}

    static Aabb empty() { return {}; }
    /// The box of every point: bounds of unbounded shapes such as planes.
    static Aabb infinite() {
        Aabb box;
        box.lower = Point3::Constant(-kInfinity);
        box.upper = Point3::Constant(kInfinity);
        return box;
    }

    bool is_empty() const {
        return !(lower.x() <= upper.x() && lower.y() <= upper.y() && lower.z() <= upper.z());
    }
    bool is_finite() const { return csgrt::is_finite(lower) && csgrt::is_finite(upper); }

    void extend(const Point3& p) {
        lower = lower.cwiseMin(p);
        upper = upper.cwiseMax(p);
    }
    void extend(const Aabb& box) {
        lower = lower.cwiseMin(box.lower);
        upper = upper.cwiseMax(box.upper);
    }

    Point3 center() const { return 0.5 * (lower + upper); }
    Vector3 diagonal() const { return upper - lower; }
    int longest_axis() const { return max_dimension(diagonal()); }
    /// Surface area, the SAH's measure of how likely a random ray is to hit the box.
    double surface_area() const {
        if (is_empty()) return 0.0;
        const Vector3 d = diagonal();
        return 2.0 * (d.x() * d.y() + d.y() * d.z() + d.z() * d.x());
    }

    /// Closed containment: points on the faces are inside.
    bool contains(const Point3& p) const {
        return (p.array() >= lower.array()).all() && (p.array() <= upper.array()).all();
    }
    bool overlaps(const Aabb& box) const {
        return (lower.array() <= box.upper.array()).all() &&
               (box.lower.array() <= upper.array()).all();
    }

    /// Slab test (Kay & Kajiya 1986) made conservative as in Ize, "Robust BVH Ray Traversal",
    /// JCGT 2(2) 2013: t_far is moved out by 2 gamma(3) |t_far|, which covers the rounding of
    /// the subtraction and product in both slab distances, so a ray that grazes the box is
    /// never culled (|t_far| rather than t_far keeps it conservative for t < 0 too). A zero
    /// direction component gives an infinite reciprocal; the NaN from 0 * inf (origin on a slab
    /// plane) is ignored by the comparisons, which keeps the test conservative. On a hit, [t_enter,
    /// t_exit] overlaps [ray.t_min, ray.t_max] and is clipped to it.
    bool intersect(const Ray& ray, const Vector3& inverse_direction, double& t_enter,
                   double& t_exit) const {
        double t0 = ray.t_min;
        double t1 = ray.t_max;
        for (int axis = 0; axis < 3; ++axis) {
            double t_near = (lower[axis] - ray.origin[axis]) * inverse_direction[axis];
            double t_far = (upper[axis] - ray.origin[axis]) * inverse_direction[axis];
            if (t_near > t_far) std::swap(t_near, t_far);
            // Scaling (not adding) keeps an infinite t_far infinite rather than NaN.
            t_far *= t_far >= 0.0 ? 1.0 + 2.0 * gamma(3) : 1.0 - 2.0 * gamma(3);
            // Written so a NaN slab leaves the interval unchanged.
            t0 = t_near > t0 ? t_near : t0;
            t1 = t_far < t1 ? t_far : t1;
            if (t0 > t1) return false;
        }
        t_enter = t0;
        t_exit = t1;
        return true;
    }

    bool intersect(const Ray& ray) const {
        double t_enter, t_exit;
        return intersect(ray, ray.direction.cwiseInverse(), t_enter, t_exit);
    }
};

/// The smallest box holding both.
inline Aabb join(const Aabb& a, const Aabb& b) {
    Aabb box = a;
    box.extend(b);
    return box;
}

/// The overlap of two boxes (empty when they are disjoint).
inline Aabb overlap(const Aabb& a, const Aabb& b) {
    Aabb box;
    box.lower = a.lower.cwiseMax(b.lower);
    box.upper = a.upper.cwiseMin(b.upper);
    return box;
}

}  // namespace csgrt
