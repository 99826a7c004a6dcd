#include "csgrt/core/part_sphere.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt {

namespace {

Sphere validated_sphere(const Point3& center, double radius) {
    require_finite(center, "PartSphere", "center");
    require_positive(radius, "PartSphere", "radius");
    return Sphere(center, radius);
}

// cos(theta), with a limit within one rounding of pi / 2 taken as the equator exactly:
// cos(double(pi / 2)) is 6e-17, not 0, which would drop the rim of a hemisphere.
double polar_cosine(double theta) {
    const double cosine = std::cos(theta);
    return std::abs(cosine) <= theta * kUnitRoundoff ? 0.0 : cosine;
}

}  // namespace

PartSphere::PartSphere(const Point3& center, double radius, double phi_min, double phi_max,
                       double theta_min, double theta_max)
    : sphere_(validated_sphere(center, radius)),
      azimuth_(phi_min, phi_max, "PartSphere"),
      theta_min_(theta_min),
      theta_max_(theta_max) {
    require(theta_min >= 0.0 && theta_min < kPi, "PartSphere", "theta_min", "in [0, pi)",
            theta_min);
    require(theta_max > theta_min && theta_max <= kPi, "PartSphere", "theta_max",
            "in (theta_min, pi]", theta_max);
    // No limit at the poles: comparing y with r cos(0) = r would reject a pole hit whose y
    // rounded to just above r.
    y_high_ = theta_min == 0.0 ? kInfinity : radius * polar_cosine(theta_min);
    y_low_ = theta_max == kPi ? -kInfinity : radius * polar_cosine(theta_max);
}

Aabb PartSphere::bounds() const {
    const double r = radius();
    // The band's widest circle: the equator if the band contains it, else its wider rim.
    const double widest = (theta_min_ <= kPi / 2 && theta_max_ >= kPi / 2)
                              ? 1.0
                              : std::max(std::sin(theta_min_), std::sin(theta_max_));
    const double pad = 1.0 + gamma(4);
    const double reach = r * widest * pad;
    const double top = std::min(y_high_, r) * (y_high_ >= 0.0 ? pad : 1.0 / pad);
    const double bottom = std::max(y_low_, -r) * (y_low_ <= 0.0 ? pad : 1.0 / pad);
    const Point3& c = center();
    Aabb box;
    box.lower =
        Point3(next_down(c.x() - reach), next_down(c.y() + bottom), next_down(c.z() - reach));
    box.upper = Point3(next_up(c.x() + reach), next_up(c.y() + top), next_up(c.z() + reach));
    return box;
}

std::optional<Crossing> PartSphere::crossing(const Ray& ray) const {
    double roots[2];
    if (!sphere_.line_roots(ray, roots[0], roots[1])) return {};
    // The nearer root may fall in the removed part; the ray then goes on to the far side.
    for (const double root : roots) {
        if (ray.in_range(root) && in_limits((ray.origin - center()) + root * ray.direction)) {
            return Crossing{.t = root};
        }
    }
    return {};
}

SurfacePoint PartSphere::surface_at(const Ray& ray, const HitRecord& record) const {
    // Project back onto the sphere, as Sphere::surface_at does.
    const Normal3 normal = sphere_.unit_along((ray.origin - center()) + record.t * ray.direction);
    const double theta = std::acos(std::clamp(normal.y(), -1.0, 1.0));
    const double v = (theta_max_ - theta) / (theta_max_ - theta_min_);
    return {center() + radius() * normal, normal,
            Vector2(azimuth_.fraction(AngleRange::azimuth(normal.x(), normal.z())),
                    std::clamp(v, 0.0, 1.0))};
}

template class detail::LeafShape<PartSphere>;

}  // namespace csgrt
