#include "csgrt/core/torus.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"
#include "csgrt/core/polynomial.h"

namespace csgrt {
namespace {

// The bounding sphere and slab clear the surface by this fraction of the minor radius, so the
// quartic is clearly positive at both ends of the interval it is solved on.
constexpr double kBoundMargin = 1.0 / 16.0;

double checked_major_radius(double major_radius, double minor_radius) {
    Torus::require_ring_radii(major_radius, minor_radius, "Torus");
    return major_radius;
}

// The tube function g(p) = (rho - R)^2 + y^2 - r^2, rho = sqrt(x^2 + z^2), along the ray:
// h(t) = g(o + t d). It vanishes on the same surface as the quartic (whose other factor,
// (rho + R)^2 + y^2 - r^2, is positive for a ring torus), but near the surface its terms are
// of size r^2 rather than R^4, so it decides and polishes roots the quartic only isolates.
struct TubeAlongRay {
    TubeAlongRay(const Ray& ray, double major, double minor)
        : origin(ray.origin),
          direction(ray.direction),
          major_radius(major),
          minor_radius(minor),
          origin_norm(ray.origin.norm()),
          direction_norm(ray.direction.norm()) {}

    // h(t), h'(t), and a bound on the rounding error of h(t): the point o + t d is off the
    // line by up to e = 2 u (|o| + |t| |d|) per coordinate; rho then by e + 2 u (rho + R)
    // after subtracting R; squaring doubles the relative error, and the sum adds a few u of
    // its terms. Near the surface (|rho - R|, |y| <= r) that is ~ 4 r (e + 2 u R): a few ulps
    // of the coordinates, times r.
    void operator()(double t, double& value, double& slope, double& error) const {
        const Point3 p = origin + t * direction;
        const double rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
        const double radial = rho - major_radius;
        const double height = p.y();
        value = radial * radial + height * height - minor_radius * minor_radius;
        // d rho / dt is undefined on the axis, where the surface is not (r < R).
        const double rho_slope =
            rho > 0.0 ? (p.x() * direction.x() + p.z() * direction.z()) / rho : 0.0;
        slope = 2.0 * (radial * rho_slope + height * direction.y());
        const double point_error =
            2.0 * kUnitRoundoff * (origin_norm + std::abs(t) * direction_norm);
        const double radial_error = point_error + 2.0 * kUnitRoundoff * (rho + major_radius);
        error = 2.0 * (std::abs(radial) * radial_error + std::abs(height) * point_error) +
                4.0 * kUnitRoundoff * (radial * radial + height * height + square(minor_radius));
    }

    double value(double t) const {
        double value, slope, error;
        (*this)(t, value, slope, error);
        return value;
    }

    const Point3& origin;
    const Vector3& direction;
    double major_radius;
    double minor_radius;
    double origin_norm;
    double direction_norm;
};

}  // namespace

void Torus::require_ring_radii(double major_radius, double minor_radius, std::string_view what) {
    require_positive(major_radius, what, "major_radius");
    require_positive(minor_radius, what, "minor_radius");
    require(minor_radius < major_radius, what, "minor_radius",
            "< major_radius (a ring torus; horn and spindle tori are not supported)", minor_radius);
}

Torus::Torus(double major_radius, double minor_radius)
    : major_radius_(checked_major_radius(major_radius, minor_radius)),
      minor_radius_(minor_radius),
      bounding_sphere_(Point3(0.0, 0.0, 0.0), major_radius + minor_radius * (1.0 + kBoundMargin)) {}

Aabb Torus::bounds() const {
    const double outer = major_radius_ + minor_radius_;
    return Aabb(Point3(-outer, -minor_radius_, -outer), Point3(outer, minor_radius_, outer));
}

int Torus::line_roots(const Ray& ray, double roots[4]) const {
    const double major = major_radius_;
    const double minor = minor_radius_;
    const Point3& origin = ray.origin;
    const Vector3& direction = ray.direction;

    // Pre-reject: the line inside the bounding sphere and the slab |y| <= r, both widened.
    double t_enter, t_exit;
    if (!bounding_sphere_.line_roots(ray, t_enter, t_exit)) return 0;
    const double slab = minor * (1.0 + kBoundMargin);
    if (direction.y() != 0.0) {
        double t_bottom = (-slab - origin.y()) / direction.y();
        double t_top = (slab - origin.y()) / direction.y();
        if (t_bottom > t_top) std::swap(t_bottom, t_top);
        t_enter = std::max(t_enter, t_bottom);
        t_exit = std::min(t_exit, t_top);
    } else if (std::abs(origin.y()) > slab) {
        return 0;
    }
    if (!(t_enter < t_exit) || t_exit < ray.t_min || t_enter > ray.t_max) return 0;

    // The quartic in the distance s = (t - t_shift) |d| from a point of the line inside the
    // bounds: its coefficients are then of size R^4 wherever the origin is (POV-Ray moves the
    // origin for the same reason) and however long d is, instead of |o|^4 with catastrophic
    // cancellation, or |d|^4 overflowing.
    const double t_shift = 0.5 * (t_enter + t_exit);
    const Point3 p = ray.at(t_shift);
    const double length = direction.norm();
    const Vector3 unit = direction / length;
    const double major2 = major * major;
    const double a = unit.squaredNorm();
    const double b = p.dot(unit);
    const double c = p.squaredNorm() + major2 - minor * minor;
    const double dxz = unit.x() * unit.x() + unit.z() * unit.z();
    const double exz = p.x() * unit.x() + p.z() * unit.z();
    const double fxz = p.x() * p.x() + p.z() * p.z();
    // (a s^2 + 2 b s + c)^2 - 4 R^2 (dxz s^2 + 2 exz s + fxz), in ascending powers of s.
    const double coeffs[5] = {c * c - 4.0 * major2 * fxz, 4.0 * b * c - 8.0 * major2 * exz,
                              4.0 * b * b + 2.0 * a * c - 4.0 * major2 * dxz, 4.0 * a * b, a * a};
    // Absolute error bounds: gamma(8) times each coefficient's sum of absolute terms (with
    // |p| = P, S = P^2 + R^2 + r^2 bounding |c|, |unit| = 1), plus the effect of the line
    // being off by e: p by 2 u (|o| + |t_shift| |d|), and the rounded unit direction by u per
    // unit of s, |s| <= R + 2 r. That is e times the coefficient's derivative in P, doubled.
    const double pn = p.norm();
    const double sum = pn * pn + major2 + minor * minor;
    const double e =
        2.0 * kUnitRoundoff * (origin.norm() + std::abs(t_shift) * length + major + 2.0 * minor);
    const double g8 = gamma(8);
    const double errors[5] = {
        g8 * (sum * sum + 4.0 * major2 * pn * pn) + 2.0 * e * (4.0 * pn * sum + 8.0 * major2 * pn),
        g8 * (4.0 * pn * sum + 8.0 * major2 * pn) +
            2.0 * e * (4.0 * (sum + 2.0 * pn * pn) + 8.0 * major2),
        g8 * (4.0 * pn * pn + 2.0 * sum + 4.0 * major2) + 2.0 * e * 12.0 * pn,
        g8 * 4.0 * pn + 2.0 * e * 4.0, g8};
    double shifted[4];
    const int count = solve_quartic(coeffs, errors, (t_enter - t_shift) * length,
                                    (t_exit - t_shift) * length, shifted);
    for (int i = 0; i < count; ++i) roots[i] = t_shift + shifted[i] / length;

    // Decide near-tangencies and polish on the tube function along the original ray. Before
    // the first root the line is outside (the quartic is positive at t_enter), and each root
    // toggles, so a root's index says which side it comes from.
    const TubeAlongRay tube(ray, major, minor);
    int kept = 0;
    double result[4];
    for (int i = 0; i < count;) {
        const double before = i > 0 ? 0.5 * (roots[i - 1] + roots[i]) : t_enter;
        // +1: the line is outside just before this root (tube > 0), -1: inside.
        const double side = i % 2 == 0 ? 1.0 : -1.0;
        if (i + 1 < count && roots[i] == roots[i + 1]) {
            // A tangency within the quartic's noise: the tube function at the touching point
            // says whether the line misses, touches, or crosses twice.
            const double touch = roots[i];
            const double after = i + 2 < count ? 0.5 * (touch + roots[i + 2]) : t_exit;
            double value, slope, noise;
            tube(touch, value, slope, noise);
            const double depth = side * value;
            if (depth > noise) {
                i += 2;  // the line passes by without reaching the surface
                continue;
            }
            if (depth < -noise && side * tube.value(before) > 0.0 &&
                side * tube.value(after) > 0.0) {
                result[kept++] = detail::bracketed_root(tube, before, touch, side < 0.0, touch);
                result[kept++] = detail::bracketed_root(tube, touch, after, side > 0.0, touch);
            } else {
                result[kept++] = touch;
                result[kept++] = touch;
            }
            i += 2;
            continue;
        }
        // A crossing: polish it inside the bracket between its neighbours, if the tube
        // function confirms the bracket (otherwise the quartic's root stands).
        const double after = i + 1 < count ? 0.5 * (roots[i] + roots[i + 1]) : t_exit;
        if (side * tube.value(before) > 0.0 && side * tube.value(after) < 0.0) {
            result[kept++] = detail::bracketed_root(tube, before, after, side < 0.0, roots[i]);
        } else {
            result[kept++] = roots[i];
        }
        ++i;
    }
    std::copy(result, result + kept, roots);
    return kept;
}

std::optional<Crossing> Torus::crossing(const Ray& ray) const {
    double roots[4];
    const int count = line_roots(ray, roots);
    for (int i = 0; i < count; ++i) {
        if (ray.in_range(roots[i])) return Crossing{.t = roots[i]};
    }
    return {};
}

void Torus::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    count_solve(scratch, *this);
    spans.clear();
    double roots[4];
    const int count = line_roots(ray, roots);
    for (int i = 0; i + 1 < count; i += 2) {
        if (roots[i + 1] < ray.t_min || roots[i] > ray.t_max) continue;
        spans.push_back(Span{HitRecord{.t = roots[i], .shape = this, .primitive = 0},
                             HitRecord{.t = roots[i + 1], .shape = this, .primitive = 0}});
    }
}

bool Torus::contains(const Point3& p) const {
    const double rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
    return square(rho - major_radius_) + p.y() * p.y() < square(minor_radius_);
}

void Torus::surface_angles(const Point3& p, double& phi, double& theta) const {
    phi = std::atan2(p.x(), p.z());
    if (phi < 0.0) phi += kTwoPi;
    theta = std::atan2(p.y(), std::sqrt(p.x() * p.x() + p.z() * p.z()) - major_radius_);
    if (theta < 0.0) theta += kTwoPi;
}

SurfacePoint Torus::surface_at(const Ray& ray, const HitRecord& record) const {
    const Point3 p = ray.at(record.t);
    // The nearest point of the core circle; the normal points from it to the hit point (the
    // gradient of the tube function, parallel to the quartic's on the surface).
    const double rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
    const Vector3 radial = rho > 0.0 ? Vector3(p.x() / rho, 0.0, p.z() / rho) : Vector3(0, 0, 1);
    const Point3 core = major_radius_ * radial;
    Vector3 normal = p - core;
    const double length = normal.norm();
    normal = length > 0.0 ? Vector3(normal / length) : radial;
    // Project back onto the surface: removes the rounding of o + t d along the normal.
    const Point3 point = core + minor_radius_ * normal;
    double phi, theta;
    surface_angles(point, phi, theta);
    return {point, normal, Vector2(phi / kTwoPi, theta / kTwoPi)};
}

template class detail::LeafShape<Torus>;

}  // namespace csgrt
