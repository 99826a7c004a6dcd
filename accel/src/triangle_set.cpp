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
    prepared.shear_z = 1.0 / direction[prepared.axis_z];
    prepared.shear_x = static_cast<Real>(direction[prepared.axis_x] / direction[prepared.axis_z]);
    prepared.shear_y = static_cast<Real>(direction[prepared.axis_y] / direction[prepared.axis_z]);
    prepared.t_min = ray.t_min;
    prepared.t_max = ray.t_max;
    return prepared;
}

template class TriangleSet<float>;
template class TriangleSet<double>;

}  // namespace csgrt
