#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "csgrt/core/aabb.h"
#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"

namespace csgrt {

/// A right-handed orthonormal frame (x_axis, normal, z_axis) around a unit normal. The flat
/// shapes measure uv and azimuth in it as y-up shapes do: local coordinates (x, y, z) =
/// (p . x_axis, p . normal, p . z_axis) and phi = atan2(x, z).
///
/// For a normal with y >= 0 the frame is the world frame turned by the smallest rotation that
/// takes +y to the normal (normal +y gives x_axis +x, z_axis +z); for y < 0 it is the world
/// frame turned half a turn about z, then by the smallest rotation taking -y to the normal.
/// The split keeps the formula's divisor >= 1 (the sign trick of Duff et al., "Building an
/// Orthonormal Basis, Revisited", JCGT 6(1) 2017).
struct SurfaceFrame {
    Vector3 x_axis{1.0, 0.0, 0.0};
    Normal3 normal{0.0, 1.0, 0.0};
    Vector3 z_axis{0.0, 0.0, 1.0};

    /// The frame of a unit normal (assumed unit length and finite).
    static SurfaceFrame around(const Normal3& unit_normal);

    /// World vector v in frame coordinates (x, y, z).
    Vector3 to_local(const Vector3& v) const {
        return Vector3(v.dot(x_axis), v.dot(normal), v.dot(z_axis));
    }
};

namespace detail {

/// v / |v|, computed after scaling by the largest component so tiny and huge vectors do not
/// underflow or overflow; the zero vector for a zero or non-finite v.
Vector3 normalized_or_zero(const Vector3& v);

/// The parameter t where the ray's line crosses the plane through `point` with unit normal
/// `normal`, t = (point - o) . n / (d . n). False when the ray is parallel to the plane (also
/// when it lies in it: such a ray never crosses it) or t is not finite.
inline bool plane_crossing(const Ray& ray, const Point3& point, const Normal3& normal, double& t) {
    const double denominator = ray.direction.dot(normal);
    if (denominator == 0.0) return false;
    t = (point - ray.origin).dot(normal) / denominator;
    return std::isfinite(t);
}

/// Conservative bounds of the disk of `radius` around `center` in the plane with unit normal
/// `normal`: along axis i it reaches radius * sqrt(1 - n_i^2), rounded outward.
Aabb disk_bounds(const Point3& center, const Normal3& normal, double radius);

}  // namespace detail

}  // namespace csgrt
