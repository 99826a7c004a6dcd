#include "csgrt/core/surface_frame.h"

#include <algorithm>
#include <cmath>

namespace csgrt {

SurfaceFrame SurfaceFrame::around(const Normal3& n) {
    // z_axis = R z for the rotation R described in the header. Written out, it is
    // (-k nx nz, -s nz, 1 - k nz^2) with s the side of the horizon and k = 1 / (1 + |ny|),
    // which never divides by less than 1.
    const double side = n.y() >= 0.0 ? 1.0 : -1.0;
    const double k = 1.0 / (1.0 + std::abs(n.y()));
    SurfaceFrame frame;
    frame.normal = n;
    frame.z_axis = Vector3(-k * n.x() * n.z(), -side * n.z(), 1.0 - k * n.z() * n.z());
    frame.x_axis = n.cross(frame.z_axis);
    return frame;
}

namespace detail {

Vector3 normalized_or_zero(const Vector3& v) {
    const double largest = v.cwiseAbs().maxCoeff();
    if (!(largest > 0.0) || !std::isfinite(largest)) return Vector3::Zero();
    return (v / largest).normalized();
}

Aabb disk_bounds(const Point3& center, const Normal3& normal, double radius) {
    Aabb box;
    for (int axis = 0; axis < 3; ++axis) {
        // sqrt(1 - n_i^2) as the norm of the other two components, which does not cancel;
        // gamma(4) covers its rounding and the product's, the ulp steps the sums'.
        const double other = std::hypot(normal[(axis + 1) % 3], normal[(axis + 2) % 3]);
        const double reach = radius * std::min(other, 1.0) * (1.0 + gamma(4));
        box.lower[axis] = next_down(center[axis] - reach);
        box.upper[axis] = next_up(center[axis] + reach);
    }
    return box;
}

}  // namespace detail

}  // namespace csgrt
