#include "csgrt/core/part_torus.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {
namespace {

double checked_major_radius(double major_radius, double minor_radius) {
    Torus::require_ring_radii(major_radius, minor_radius, "PartTorus");
    return major_radius;
}

// Validates [min, max] and returns min wrapped into [0, 2 pi).
double checked_range_start(double min, double max, std::string_view min_name,
                           std::string_view max_name) {
    require_finite(min, "PartTorus", min_name);
    require_finite(max, "PartTorus", max_name);
    require(max > min && max - min <= kTwoPi, "PartTorus", max_name,
            "in (min, min + 2 pi] for its range", max);
    const double wrapped = std::fmod(min, kTwoPi);
    return wrapped < 0.0 ? wrapped + kTwoPi : wrapped;
}

// angle - start wrapped into [0, 2 pi), for angle and start in [0, 2 pi).
double offset_from(double angle, double start) {
    const double offset = angle - start;
    return offset < 0.0 ? offset + kTwoPi : offset;
}

// An offset as a fraction of its range's width; an offset past the width (a point found in
// range, rounded out of it) goes to the nearer end, across the seam if need be.
double fraction_of(double offset, double width) {
    if (offset <= width) return offset / width;
    return kTwoPi - offset < offset - width ? 0.0 : 1.0;
}

}  // namespace

PartTorus::PartTorus(double major_radius, double minor_radius, double phi_min, double phi_max,
                     double theta_min, double theta_max)
    : torus_(checked_major_radius(major_radius, minor_radius), minor_radius),
      phi_min_(checked_range_start(phi_min, phi_max, "phi_min", "phi_max")),
      phi_width_(phi_max - phi_min),
      theta_min_(checked_range_start(theta_min, theta_max, "theta_min", "theta_max")),
      theta_width_(theta_max - theta_min) {}

void PartTorus::angle_offsets(const Point3& p, double& phi_offset, double& theta_offset) const {
    double phi, theta;
    torus_.surface_angles(p, phi, theta);
    phi_offset = offset_from(phi, phi_min_);
    theta_offset = offset_from(theta, theta_min_);
}

bool PartTorus::keeps(const Point3& p) const {
    double phi_offset, theta_offset;
    angle_offsets(p, phi_offset, theta_offset);
    return phi_offset <= phi_width_ && theta_offset <= theta_width_;
}

bool PartTorus::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch&) const {
    double roots[4];
    const int count = torus_.line_roots(ray, roots);
    for (int i = 0; i < count; ++i) {
        if (ray.in_range(roots[i]) && keeps(ray.at(roots[i]))) {
            record = HitRecord{.t = roots[i], .shape = this, .primitive = 0};
            return true;
        }
    }
    return false;
}

bool PartTorus::any_hit(const Ray& ray, QueryScratch& scratch) const {
    HitRecord record;
    return nearest_hit(ray, record, scratch);
}

Hit PartTorus::finish(const Ray& ray, const HitRecord& record) const {
    Hit hit = torus_.finish(ray, record);
    double phi_offset, theta_offset;
    angle_offsets(hit.point, phi_offset, theta_offset);
    hit.uv = Vector2(fraction_of(phi_offset, phi_width_), fraction_of(theta_offset, theta_width_));
    hit.shape = this;
    return hit;
}

}  // namespace csgrt
