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

template class TriangleSet<float>;
template class TriangleSet<double>;

}  // namespace csgrt
