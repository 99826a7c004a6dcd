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

// AzimuthRange names its limits phi_min and phi_max: theta's are checked here first, by the
// same rules, so that a message names the right parameter.
AzimuthRange checked_theta_range(double theta_min, double theta_max) {
    require(theta_min >= 0.0 && theta_min < kTwoPi, "PartTorus", "theta_min", "in [0, 2 pi)",
            theta_min);
    require(theta_max > theta_min && theta_max <= theta_min + kTwoPi, "PartTorus", "theta_max",
            "in (theta_min, theta_min + 2 pi]", theta_max);
    return AzimuthRange(theta_min, theta_max, "PartTorus");
}

// The ranges of cos and sin over [start, end], start in [0, 2 pi), end <= start + 2 pi: their
// values at the ends and at the quarter turns inside.
void cos_sin_ranges(double start, double end, double& cos_lo, double& cos_hi, double& sin_lo,
                    double& sin_hi) {
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
      phi_range_(phi_min, phi_max, "PartTorus"),
      theta_range_(checked_theta_range(theta_min, theta_max)) {
    // A surface point is (rho sin phi, r sin theta, rho cos phi) with rho = R + r cos theta.
    double cos_theta_lo, cos_theta_hi, sin_theta_lo, sin_theta_hi;
    cos_sin_ranges(theta_min, theta_max, cos_theta_lo, cos_theta_hi, sin_theta_lo, sin_theta_hi);
    double cos_phi_lo, cos_phi_hi, sin_phi_lo, sin_phi_hi;
    cos_sin_ranges(phi_min, phi_max, cos_phi_lo, cos_phi_hi, sin_phi_lo, sin_phi_hi);
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

bool PartTorus::keeps(const Point3& p) const {
    const double rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
    return phi_range_.contains(p.x(), p.z()) &&
           theta_range_.contains(p.y(), rho - torus_.major_radius());
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
    double phi, theta;
    torus_.surface_angles(hit.point, phi, theta);
    hit.uv = Vector2(phi_range_.fraction(phi), theta_range_.fraction(theta));
    hit.shape = this;
    return hit;
}

}  // namespace csgrt
