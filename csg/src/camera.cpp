#include "csgrt/csg/camera.h"

#include <Eigen/Geometry>

#include "csgrt/core/error.h"

namespace csgrt {

void Camera::validate() const {
    require_finite(position, "Camera", "position");
    require_finite(look_at, "Camera", "look_at");
    require_finite(up, "Camera", "up");
    const Vector3 forward = look_at - position;
    require(forward.squaredNorm() > 0.0, "Camera", "look_at", "different from position", look_at);
    require(forward.normalized().cross(up).squaredNorm() > 1e-12 * up.squaredNorm() &&
                up.squaredNorm() > 0.0,
            "Camera", "up", "non-zero and not parallel to the view direction", up);
    if (projection == Projection::Pinhole) {
        require(vertical_fov_degrees > 0.0 && vertical_fov_degrees < 180.0, "Camera",
                "vertical_fov_degrees", "in (0, 180)", vertical_fov_degrees);
    } else {
        require_positive(orthographic_height, "Camera", "orthographic_height");
    }
}

Ray Camera::generate_ray(double x, double y, double aspect) const {
    // An orthonormal frame: forward into the scene, right and down along the film's axes.
    const Vector3 forward = (look_at - position).normalized();
    const Vector3 right = forward.cross(up).normalized();
    const Vector3 down = forward.cross(right);
    const double film_x = (2.0 * x - 1.0) * aspect;
    const double film_y = 2.0 * y - 1.0;
    Ray ray;
    if (projection == Projection::Pinhole) {
        const double half_height = std::tan(0.5 * vertical_fov_degrees * kPi / 180.0);
        ray.origin = position;
        ray.direction =
            (forward + half_height * (film_x * right + film_y * down)).normalized();
    } else {
        const double half_height = 0.5 * orthographic_height;
        ray.origin = position + half_height * (film_x * right + film_y * down);
        ray.direction = forward;
    }
    return ray;
}

}  // namespace csgrt
