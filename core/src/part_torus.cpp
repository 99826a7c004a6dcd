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

// The ranges of cos and sin over [start, start + width], start in [0, 2 pi), width <= 2 pi:
// their values at the ends and at the quarter turns inside.
void cos_sin_ranges(double start, double width, double& cos_lo, double& cos_hi, double& sin_lo,
                    double& sin_hi) {
    const double end = start + width;
    cos_lo = std::min(std::cos(start), std::cos(end));
    cos_hi = std::max(std::cos(start), std::cos(end));
    sin_lo = std::min(std::sin(start), std::sin(end));
    sin_hi = std::max(std::sin(start), std::sin(end));
    constexpr double kQuarterCos[4] = {1, 0, -1, 0};
    constexpr double kQuarterSin[4] = {0, 1, 0, -1};
    for (int quarter = 0; quarter <= 8; ++quarter) {
        const double angle = quarter * (kPi / 2);
        if (angle < start || angle > end) continue;
        cos_lo = std::min(cos_lo, kQuarterCos[quarter % 4]);
        cos_hi = std::max(cos_hi, kQuarterCos[quarter % 4]);
        sin_lo = std::min(sin_lo, kQuarterSin[quarter % 4]);
        sin_hi = std::max(sin_hi, kQuarterSin[quarter % 4]);
    }
}

// The range of a b for a in [a_lo, a_hi] with a_lo > 0 and b in [b_lo, b_hi].
void product_range(double a_lo, double a_hi, double b_lo, double b_hi, double& lo, double& hi) {
    lo = b_lo >= 0.0 ? a_lo * b_lo : a_hi * b_lo;
    hi = b_hi >= 0.0 ? a_hi * b_hi : a_lo * b_hi;
}

}  // namespace

PartTorus::PartTorus(double major_radius, double minor_radius, double phi_min, double phi_max,
                     double theta_min, double theta_max)
    : torus_(checked_major_radius(major_radius, minor_radius), minor_radius),
      phi_min_(checked_range_start(phi_min, phi_max, "phi_min", "phi_max")),
      phi_width_(phi_max - phi_min),
      theta_min_(checked_range_start(theta_min, theta_max, "theta_min", "theta_max")),
      theta_width_(theta_max - theta_min) {
    // A surface point is (rho sin phi, r sin theta, rho cos phi) with rho = R + r cos theta.
    double cos_theta_lo, cos_theta_hi, sin_theta_lo, sin_theta_hi;
    cos_sin_ranges(theta_min_, theta_width_, cos_theta_lo, cos_theta_hi, sin_theta_lo,
                   sin_theta_hi);
    double cos_phi_lo, cos_phi_hi, sin_phi_lo, sin_phi_hi;
    cos_sin_ranges(phi_min_, phi_width_, cos_phi_lo, cos_phi_hi, sin_phi_lo, sin_phi_hi);
    const double rho_lo = major_radius + minor_radius * cos_theta_lo;
    const double rho_hi = major_radius + minor_radius * cos_theta_hi;
    double x_lo, x_hi, z_lo, z_hi;
    product_range(rho_lo, rho_hi, sin_phi_lo, sin_phi_hi, x_lo, x_hi);
    product_range(rho_lo, rho_hi, cos_phi_lo, cos_phi_hi, z_lo, z_hi);
    // The sines and cosines above are rounded, and so are hit points projected on the surface.
    const Vector3 pad = Vector3::Constant(32.0 * kUnitRoundoff * (major_radius + minor_radius));
    bounds_ = Aabb(Point3(x_lo, minor_radius * sin_theta_lo, z_lo) - pad,
                   Point3(x_hi, minor_radius * sin_theta_hi, z_hi) + pad);
}

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
