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
    return CameraFilm(*this, aspect).ray(x, y);
}

CameraFilm::CameraFilm(const Camera& camera, double aspect)
    : pinhole_(camera.projection == Camera::Projection::Pinhole),
      position_(camera.position),
      aspect_(aspect) {
    // An orthonormal frame: forward into the scene, right and down along the film's axes.
    forward_ = (camera.look_at - camera.position).normalized();
    right_ = forward_.cross(camera.up).normalized();
    down_ = forward_.cross(right_);
    half_height_ = pinhole_ ? std::tan(0.5 * camera.vertical_fov_degrees * kPi / 180.0)
                            : 0.5 * camera.orthographic_height;
}

Ray CameraFilm::ray(double x, double y) const {
    const double film_x = (2.0 * x - 1.0) * aspect_;
    const double film_y = 2.0 * y - 1.0;
    Ray ray;
    if (pinhole_) {
        ray.origin = position_;
        ray.direction = (forward_ + half_height_ * (film_x * right_ + film_y * down_)).normalized();
    } else {
        ray.origin = position_ + half_height_ * (film_x * right_ + film_y * down_);
        ray.direction = forward_;
    }
    return ray;
}

}  // namespace csgrt
