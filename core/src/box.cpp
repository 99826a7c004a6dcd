#include "csgrt/core/box.h"

#include <algorithm>
#include <utility>

#include "csgrt/core/error.h"

namespace csgrt {

Box::Box(const Point3& lower, const Point3& upper) : lower_(lower), upper_(upper) {
    require_finite(lower, "Box", "lower");
    require_finite(upper, "Box", "upper");
    require((lower.array() < upper.array()).all(), "Box", "upper", "> lower on every axis", upper);
}

bool Box::line_interval(const Ray& ray, double& t_enter, double& t_exit, int& enter_face,
                        int& exit_face) const {
    // The slab method (Kay and Kajiya, "Ray Tracing Complex Scenes", SIGGRAPH 1986): the line
    // is inside the box where it is inside all three slabs. Divisions rather than multiplying
    // by 1 / d: one rounding, so a ray aimed along an axis at a face gets that face exactly.
    t_enter = -kInfinity;
    t_exit = kInfinity;
    enter_face = exit_face = -1;
    for (int axis = 0; axis < 3; ++axis) {
        const double origin = ray.origin[axis];
        const double direction = ray.direction[axis];
        if (direction == 0.0) {
            // Parallel to the slab: inside it everywhere or nowhere. Closed, so a line in a
            // face plane is inside (written so NaN falls outside).
            if (!(origin >= lower_[axis] && origin <= upper_[axis])) return false;
            continue;
        }
        double t_near = (lower_[axis] - origin) / direction;
        double t_far = (upper_[axis] - origin) / direction;
        int near_face = 2 * axis, far_face = 2 * axis + 1;
        if (direction < 0.0) {
            std::swap(t_near, t_far);
            std::swap(near_face, far_face);
        }
        // Strict comparisons: on a tie (an edge or corner) the lower axis keeps the face.
        if (enter_face < 0 || t_near > t_enter) {
            t_enter = t_near;
            enter_face = near_face;
        }
        if (exit_face < 0 || t_far < t_exit) {
            t_exit = t_far;
            exit_face = far_face;
        }
    }
    // A valid ray has a non-zero direction component, so both faces are set; NaN fails here.
    return enter_face >= 0 && t_enter <= t_exit;
}

std::optional<Crossing> Box::crossing(const Ray& ray) const {
    double t_enter, t_exit;
    int enter_face, exit_face;
    if (!line_interval(ray, t_enter, t_exit, enter_face, exit_face)) return {};
    // From inside (t_enter < t_min) the nearest hit is where the ray leaves.
    if (ray.in_range(t_enter)) {
        return Crossing{.t = t_enter, .primitive = static_cast<std::uint32_t>(enter_face)};
    }
    if (ray.in_range(t_exit)) {
        return Crossing{.t = t_exit, .primitive = static_cast<std::uint32_t>(exit_face)};
    }
    return {};
}

void Box::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    count_solve(scratch, *this);
    spans.clear();
    double t_enter, t_exit;
    int enter_face, exit_face;
    if (!line_interval(ray, t_enter, t_exit, enter_face, exit_face)) return;
    if (t_exit < ray.t_min || t_enter > ray.t_max) return;
    spans.push_back(Span{
        HitRecord{.t = t_enter, .shape = this, .primitive = static_cast<std::uint32_t>(enter_face)},
        HitRecord{.t = t_exit, .shape = this, .primitive = static_cast<std::uint32_t>(exit_face)}});
}

bool Box::contains(const Point3& p) const {
    return (p.array() >= lower_.array()).all() && (p.array() <= upper_.array()).all();
}

SurfacePoint Box::surface_at(const Ray& ray, const HitRecord& record) const {
    const int face = static_cast<int>(record.primitive);
    const int axis = face / 2;
    const bool upper_side = face % 2 == 1;
    // o + t d rounded, then put exactly on the face and clamped into its rectangle.
    Point3 point = ray.at(record.t).cwiseMax(lower_).cwiseMin(upper_);
    point[axis] = upper_side ? upper_[axis] : lower_[axis];
    Normal3 normal = Normal3::Zero();
    normal[axis] = upper_side ? 1.0 : -1.0;
    const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
    const Vector2 uv((point[u_axis] - lower_[u_axis]) / (upper_[u_axis] - lower_[u_axis]),
                     (point[v_axis] - lower_[v_axis]) / (upper_[v_axis] - lower_[v_axis]));
    return {point, normal, uv.cwiseMax(0.0).cwiseMin(1.0)};
}

template class detail::LeafShape<Box>;

}  // namespace csgrt
