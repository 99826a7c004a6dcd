#pragma once

#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"

namespace csgrt {

struct Camera;

/// A camera prepared for one image: its frame and film scale computed once, so a ray costs a
/// few multiplications and one normalisation. Gives exactly Camera::generate_ray's rays.
class CameraFilm {
public:
    /// The camera must be valid (Camera::validate); aspect = width / height > 0.
    CameraFilm(const Camera& camera, double aspect);

    /// The primary ray through film point (x, y) in [0, 1]^2, x right, y down.
    Ray ray(double x, double y) const;

private:
    bool pinhole_;
    Point3 position_;
    Vector3 forward_, right_, down_;
    double half_height_, aspect_;
};

/// A camera as a scene describes it: where it stands, what it looks at, and its projection.
/// Rays are generated through film coordinates (x, y) in [0, 1]^2, x to the right and y down
/// (pixel order), for an image of a given aspect ratio (width / height).
struct Camera {
    enum class Projection { Pinhole, Orthographic };

    Projection projection = Projection::Pinhole;
    Point3 position{0.0, 0.0, 5.0};
    Point3 look_at{0.0, 0.0, 0.0};
    Vector3 up{0.0, 1.0, 0.0};
    /// Pinhole: the vertical field of view, in degrees, in (0, 180).
    double vertical_fov_degrees = 40.0;
    /// Orthographic: the height of the view, in world units.
    double orthographic_height = 2.0;

    /// Throws InvalidParameter naming the field: non-finite values, look_at == position, up
    /// parallel to the view direction, a field of view outside (0, 180), a height <= 0.
    void validate() const;

    /// The primary ray through film point (x, y): unit direction, interval [0, inf). Pinhole rays
    /// start at `position`; orthographic rays start on the plane through `position`
    /// perpendicular to the view direction.
    /// For many rays of one image, prepare a CameraFilm once instead.
    Ray generate_ray(double x, double y, double aspect) const;
};

}  // namespace csgrt
