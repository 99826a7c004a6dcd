#include "csgrt/accel/triangle_set.h"

#include <cmath>

namespace csgrt {

template <class Real>
TriangleSet<Real>::TriangleSet(std::span<const Eigen::Vector3d> vertices,
                               std::span<const std::array<std::uint32_t, 3>> triangles) {
    corners_.reserve(triangles.size());
    for (const auto& triangle : triangles) {
        corners_.push_back({vertices[triangle[0]].cast<Real>(), vertices[triangle[1]].cast<Real>(),
                            vertices[triangle[2]].cast<Real>()});
    }
}

template <class Real>
Aabb TriangleSet<Real>::bounds(std::size_t i) const {
    Aabb box;
    for (const Vector& corner : corners_[i]) box.extend(corner.template cast<double>());
    return box;
}

template <class Real>
Point3 TriangleSet<Real>::centroid(std::size_t i) const {
    const auto& c = corners_[i];
    return (c[0].template cast<double>() + c[1].template cast<double>() +
            c[2].template cast<double>()) /
           3.0;
}

template <class Real>
typename TriangleSet<Real>::PreparedRay TriangleSet<Real>::prepare(const Ray& ray,
                                                                   QueryScratch&) const {
    PreparedRay prepared;
    prepared.origin = ray.origin.cast<Real>();
    // z is the dominant direction axis, so the shear never divides by a small number; x and y
    // follow cyclically (the winding is carried by the sign of det, not by a swap).
    prepared.axis_z = max_dimension(ray.direction);
    prepared.axis_x = (prepared.axis_z + 1) % 3;
    prepared.axis_y = (prepared.axis_x + 1) % 3;
    // The ratios are formed in double and rounded once.
    const Vector3& direction = ray.direction;
    prepared.shear_z = static_cast<Real>(1.0 / direction[prepared.axis_z]);
    prepared.shear_x = static_cast<Real>(direction[prepared.axis_x] / direction[prepared.axis_z]);
    prepared.shear_y = static_cast<Real>(direction[prepared.axis_y] / direction[prepared.axis_z]);
    prepared.t_min = ray.t_min;
    prepared.t_max = ray.t_max;
    return prepared;
}

template <class Real>
bool TriangleSet<Real>::hit(std::size_t i, const PreparedRay& ray, double& t, double& b1,
                            double& b2) const {
    const auto& c = corners_[i];
    const int kx = ray.axis_x, ky = ray.axis_y, kz = ray.axis_z;
    // Corners relative to the origin, sheared so the ray runs along +z from (0, 0, 0).
    const Vector a = c[0] - ray.origin;
    const Vector b = c[1] - ray.origin;
    const Vector d = c[2] - ray.origin;
    const Real ax = a[kx] - ray.shear_x * a[kz], ay = a[ky] - ray.shear_y * a[kz];
    const Real bx = b[kx] - ray.shear_x * b[kz], by = b[ky] - ray.shear_y * b[kz];
    const Real cx = d[kx] - ray.shear_x * d[kz], cy = d[ky] - ray.shear_y * d[kz];
    // Edge functions: twice the signed areas of the ray's footprint with each edge. Triangles
    // that share an edge compute that edge's function from identical inputs, identically.
    Real u = cx * by - cy * bx;
    Real v = ax * cy - ay * cx;
    Real w = bx * ay - by * ax;
    if constexpr (std::is_same_v<Real, float>) {
        // An exact zero in float may be a rounding artefact; redo those products in double,
        // which is exact for products of floats (Woop et al., section 3).
        if (u == 0.0f || v == 0.0f || w == 0.0f) {
            u = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
            v = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
            w = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
        }
    }
    // Mixed signs: the footprint is outside. Zeros count as inside, so edges are shared.
    if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return false;
    const Real determinant = u + v + w;
    if (determinant == Real(0)) return false;  // edge-on or degenerate
    const Real az = ray.shear_z * a[kz], bz = ray.shear_z * b[kz], cz = ray.shear_z * d[kz];
    const Real scaled_t = u * az + v * bz + w * cz;
    // The division happens only for triangles the ray crosses; comparing t itself (not the
    // scaled form) keeps the tie rule exact.
    const double inverse = 1.0 / double(determinant);
    t = double(scaled_t) * inverse;
    b1 = double(v) * inverse;
    b2 = double(w) * inverse;
    return true;
}

template <class Real>
bool TriangleSet<Real>::intersect(std::size_t i, const PreparedRay& ray, HitRecord& record) const {
    double t, b1, b2;
    if (!hit(i, ray, t, b1, b2)) return false;
    const auto index = static_cast<std::uint32_t>(i);
    if (!(t >= ray.t_min && (t < record.t || (t == record.t && index < record.primitive))))
        return false;
    record.t = t;
    record.primitive = index;
    record.u = static_cast<float>(b1);
    record.v = static_cast<float>(b2);
    return true;
}

template <class Real>
bool TriangleSet<Real>::occluded(std::size_t i, const PreparedRay& ray) const {
    double t, b1, b2;
    return hit(i, ray, t, b1, b2) && t >= ray.t_min && t <= ray.t_max;
}

template class TriangleSet<float>;
template class TriangleSet<double>;

}  // namespace csgrt
