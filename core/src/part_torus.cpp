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
      theta_range_(theta_min, theta_max, "PartTorus", "theta_min", "theta_max") {
    // A surface point is (rho sin phi, r sin theta, rho cos phi) with rho = R + r cos theta.
    double cos_theta_lo, cos_theta_hi, sin_theta_lo, sin_theta_hi;
    theta_range_.sine_cosine_bounds(sin_theta_lo, sin_theta_hi, cos_theta_lo, cos_theta_hi);
    double cos_phi_lo, cos_phi_hi, sin_phi_lo, sin_phi_hi;
    phi_range_.sine_cosine_bounds(sin_phi_lo, sin_phi_hi, cos_phi_lo, cos_phi_hi);
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

std::optional<Crossing> PartTorus::crossing(const Ray& ray) const {
    double roots[4];
    const int count = torus_.line_roots(ray, roots);
    for (int i = 0; i < count; ++i) {
        if (ray.in_range(roots[i]) && keeps(ray.at(roots[i]))) return Crossing{.t = roots[i]};
    }
    return {};
}

SurfacePoint PartTorus::surface_at(const Ray& ray, const HitRecord& record) const {
    SurfacePoint surface = torus_.surface_at(ray, record);
    double phi, theta;
    torus_.surface_angles(surface.point, phi, theta);
    surface.uv = Vector2(phi_range_.fraction(phi), theta_range_.fraction(theta));
    return surface;
}

template class detail::LeafShape<PartTorus>;

}  // namespace csgrt
