#include "csgrt/render/shadow_offset.h"

#include <algorithm>
#include <cmath>

namespace csgrt {

double ray_offset_distance(const Point3& p, double scene_magnitude) {
    const double magnitude =
        std::max(p.cwiseAbs().maxCoeff(), kRayOffsetSceneFraction * std::abs(scene_magnitude));
    return kRayOffsetRelative * magnitude;
}

Point3 offset_ray_origin(const Point3& p, const Normal3& normal, double scene_magnitude) {
    // The rounding of p + distance * normal (half an ulp of the largest coordinate per axis) is
    // 2^-37 of the distance, so the point moves by the distance to within that.
    return p + ray_offset_distance(p, scene_magnitude) * normal;
}

double spawn_offset_distance(const Hit& hit, const Normal3& side) {
    // The point error bounds each coordinate; |n|_1 e is how far the error box reaches along n.
    return side.cwiseAbs().sum() * hit.point_error;
}

Point3 spawn_ray_origin(const Hit& hit, const Normal3& side) {
    const double distance = spawn_offset_distance(hit, side);
    Point3 origin = hit.point + distance * side;
    for (int axis = 0; axis < 3; ++axis) {
        if (side[axis] > 0.0) {
            origin[axis] = std::nextafter(origin[axis], kInfinity);
        } else if (side[axis] < 0.0) {
            origin[axis] = std::nextafter(origin[axis], -kInfinity);
        }
    }
    return origin;
}

}  // namespace csgrt
