#pragma once

// Long double descriptions of every core shape, written from the shapes' documented geometry
// (docs/shapes.md) and not from their code: the reference the numerical stress tests judge
// the double-precision shapes against. Each shape is a list of patches (a plane or a quadric
// or the torus's quartic, with a trim), and the reference reports every place the ray's line
// crosses each untrimmed patch, with how far the crossing lies from the patch's trim and how
// steeply the ray meets the surface there. Long double has u = 2^-64, 2048 times finer than
// double, so its own error is negligible next to the bounds the tests allow double.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

#include "csgrt/core/math.h"
#include "csgrt/core/polynomial.h"
#include "csgrt/core/ray.h"

namespace csgrt::test {

using Long = long double;
using LongVector = Eigen::Matrix<Long, 3, 1>;
using LongMatrix = Eigen::Matrix<Long, 3, 3>;

inline constexpr Long kLongPi = 3.14159265358979323846264338327950288L;
inline constexpr Long kLongInfinity = std::numeric_limits<Long>::infinity();

/// A ray in long double: a double ray converted exactly, or mapped into an object's space.
struct LongRay {
    LongVector origin;
    LongVector direction;
    LongVector at(Long t) const { return origin + t * direction; }
};

inline LongRay to_long(const Ray& ray) {
    return {ray.origin.cast<Long>(), ray.direction.cast<Long>()};
}

/// One place where the ray's line crosses the untrimmed surface of a patch.
struct Crossing {
    Long t = 0;
    /// |cos| of the angle between the ray and the surface normal there.
    Long cosine = 1;
    /// Signed distance (object units) from the crossing to the patch's trim: >= 0 where the
    /// patch keeps it. +infinity for an untrimmed patch.
    Long trim_distance = kLongInfinity;
};

/// Where the line passes close to touching a curved patch (an extremum of the patch's function
/// along the line), or close to a singular point (a cone's apex): within rounding of it, the
/// double computation cannot tell a touch from a near miss or a crossing.
struct NearTangency {
    Long t = 0;
    /// Distance (object units) from the line to the surface (or the singular point) there.
    Long distance = kLongInfinity;
    /// Signed distance from that point to the patch's trim, as for Crossing.
    Long trim_distance = kLongInfinity;
};

struct LineCrossings {
    std::vector<Crossing> crossings;
    std::vector<NearTangency> tangencies;
};

/// Signed distance from a point to a trim: >= 0 inside.
using Trim = std::function<Long(const LongVector& local)>;

/// The long double model of one shape in its own space.
class ReferenceShape {
public:
    virtual ~ReferenceShape() = default;
    /// Appends every crossing of the line with every patch, trimmed away or not.
    virtual void crossings(const LongRay& ray, LineCrossings& out) const = 0;
};

/// The distance of an angle from the limits of [min, max] (radians, max <= min + 2 pi, the
/// AngleRange rules), as a length on a circle of `radius`: positive inside the range, negative
/// outside, +infinity for the full circle.
inline Long angle_trim(Long angle, double min, double max, Long radius) {
    const Long two_pi = 2 * kLongPi;
    if (static_cast<Long>(max) - static_cast<Long>(min) >= two_pi) return kLongInfinity;
    Long offset = std::fmod(angle - static_cast<Long>(min), two_pi);
    if (offset < 0) offset += two_pi;
    const Long extent = static_cast<Long>(max) - static_cast<Long>(min);
    const Long inside = std::min(offset, extent - offset);
    const Long outside = std::min(offset - extent, two_pi - offset);
    const Long angular = offset <= extent ? inside : -outside;
    // A point at angular distance a from a limit ray lies r sin(a) from it (r when a > pi/2).
    const Long length = radius * std::sin(std::min(std::abs(angular), kLongPi / 2));
    return angular >= 0 ? length : -length;
}

/// atan2(x, z) in [0, 2 pi): the y-up azimuth.
inline Long azimuth(Long x, Long z) {
    Long angle = std::atan2(x, z);
    if (angle < 0) angle += 2 * kLongPi;
    return angle;
}

/// A flat patch: the plane through `point` with normal `normal`, trimmed.
struct PlanePatch {
    LongVector point;
    LongVector normal;  // unit
    Trim trim;          // of the point relative to `point`; null: untrimmed

    void crossings(const LongRay& ray, LineCrossings& out) const {
        const Long denominator = ray.direction.dot(normal);
        if (denominator == 0) return;  // parallel: no single crossing
        const Long t = (point - ray.origin).dot(normal) / denominator;
        if (!std::isfinite(t)) return;
        const Long cosine = std::abs(denominator) / ray.direction.norm();
        out.crossings.push_back({t, cosine, trim ? trim(ray.at(t) - point) : kLongInfinity});
    }
};

/// A quadric patch f(x) = x' M x + 2 q . x + k = 0 in coordinates x = p - center, with M
/// diagonal, trimmed. The line is moved to its closest approach to `center` first, so the
/// coefficients are of the patch's size however far away the origin is.
struct QuadricPatch {
    LongVector center;
    LongVector diagonal;
    LongVector linear;
    Long constant = 0;
    Trim trim;

    Long value(const LongVector& x) const {
        return x.dot(diagonal.cwiseProduct(x)) + 2 * linear.dot(x) + constant;
    }
    LongVector gradient(const LongVector& x) const {
        return 2 * (diagonal.cwiseProduct(x) + linear);
    }

    void crossings(const LongRay& ray, LineCrossings& out) const {
        const LongVector& d = ray.direction;
        const LongVector from_center = ray.origin - center;
        const Long shift = -from_center.dot(d) / d.squaredNorm();
        const LongVector x0 = from_center + shift * d;
        const LongVector md = diagonal.cwiseProduct(d);
        const Long a = d.dot(md);
        const Long b = 2 * (x0.dot(md) + linear.dot(d));
        const Long c = value(x0);
        auto kept = [&](Long s) { return trim ? trim(x0 + s * d) : kLongInfinity; };
        Long roots[2];
        const int count = solve_quadratic(a, b, c, roots);
        for (int i = 0; i < count; ++i) {
            const LongVector x = x0 + roots[i] * d;
            const LongVector g = gradient(x);
            const Long g_norm = g.norm();
            const Long cosine = g_norm > 0 ? std::abs(g.dot(d)) / (g_norm * d.norm()) : 0;
            out.crossings.push_back({shift + roots[i], cosine, kept(roots[i])});
        }
        if (a != 0) {
            // The extremum of f along the line: |f| / |grad f| there is the distance to the
            // surface to first order, which is what decides touch or miss.
            const Long s = -b / (2 * a);
            const LongVector x = x0 + s * d;
            const Long g_norm = gradient(x).norm();
            const Long f = value(x);
            const Long distance =
                g_norm > 0 ? std::abs(f) / g_norm : (f == 0 ? Long(0) : kLongInfinity);
            out.tangencies.push_back({shift + s, distance, kept(s)});
        }
    }
};

/// The ring torus about the y axis: (|p|^2 + R^2 - r^2)^2 = 4 R^2 (x^2 + z^2), trimmed. Its
/// quartic is built around the line's point nearest the centre, solved by the long double
/// solve_quartic on the chord of the sphere of radius R + 2 r, and each root polished by
/// Newton on the tube function (rho - R)^2 + y^2 - r^2 along the line.
struct TorusPatch {
    Long major = 1;
    Long minor = 0.25;
    Trim trim;

    Long tube(const LongVector& p) const {
        const Long rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
        return (rho - major) * (rho - major) + p.y() * p.y() - minor * minor;
    }
    Long surface_distance(const LongVector& p) const {
        const Long rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
        return std::sqrt((rho - major) * (rho - major) + p.y() * p.y()) - minor;
    }
    LongVector normal(const LongVector& p) const {
        const Long rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
        return LongVector(p.x() * (rho - major) / rho, p.y(), p.z() * (rho - major) / rho)
            .normalized();
    }

    void crossings(const LongRay& ray, LineCrossings& out) const {
        const LongVector& o = ray.origin;
        const LongVector& d = ray.direction;
        const Long a = d.squaredNorm();
        const Long t_center = -o.dot(d) / a;
        const LongVector p = o + t_center * d;
        const Long reach = major + 2 * minor;
        if (p.squaredNorm() >= reach * reach) return;
        const Long half_chord = std::sqrt((reach * reach - p.squaredNorm()) / a);
        const Long b = p.dot(d);
        const Long c = p.squaredNorm() + major * major - minor * minor;
        const Long dxz = d.x() * d.x() + d.z() * d.z();
        const Long exz = p.x() * d.x() + p.z() * d.z();
        const Long fxz = p.x() * p.x() + p.z() * p.z();
        const Long r2 = major * major;
        const Long coeffs[5] = {c * c - 4 * r2 * fxz, 4 * b * c - 8 * r2 * exz,
                                4 * b * b + 2 * a * c - 4 * r2 * dxz, 4 * a * b, a * a};
        Long roots[4];
        const int count = solve_quartic(coeffs, -half_chord, half_chord, roots);
        for (int i = 0; i < count; ++i) {
            Long t = t_center + roots[i];
            const bool tangent =
                (i > 0 && roots[i - 1] == roots[i]) || (i + 1 < count && roots[i + 1] == roots[i]);
            for (int step = 0; step < 4 && !tangent; ++step) {
                const LongVector q = o + t * d;
                const Long rho = std::sqrt(q.x() * q.x() + q.z() * q.z());
                const Long slope =
                    2 * ((rho - major) * (q.x() * d.x() + q.z() * d.z()) / rho + q.y() * d.y());
                if (slope == 0) break;
                t -= tube(q) / slope;
            }
            const LongVector q = o + t * d;
            const Long cosine = std::abs(normal(q).dot(d)) / std::sqrt(a);
            out.crossings.push_back({t, cosine, trim ? trim(q) : kLongInfinity});
        }
        Long extrema[3];
        const int extremum_count =
            solve_cubic(4 * coeffs[4], 3 * coeffs[3], 2 * coeffs[2], coeffs[1], extrema);
        for (int i = 0; i < extremum_count; ++i) {
            if (std::abs(extrema[i]) > half_chord) continue;
            const Long t = t_center + extrema[i];
            const LongVector q = o + t * d;
            out.tangencies.push_back(
                {t, std::abs(surface_distance(q)), trim ? trim(q) : kLongInfinity});
        }
    }
};

/// A shape made of patches (and singular points: a cone's apex).
class PatchShape final : public ReferenceShape {
public:
    std::vector<PlanePatch> planes;
    std::vector<QuadricPatch> quadrics;
    std::vector<TorusPatch> tori;
    std::vector<LongVector> singular_points;

    void crossings(const LongRay& ray, LineCrossings& out) const override {
        for (const PlanePatch& patch : planes) patch.crossings(ray, out);
        for (const QuadricPatch& patch : quadrics) patch.crossings(ray, out);
        for (const TorusPatch& patch : tori) patch.crossings(ray, out);
        for (const LongVector& point : singular_points) {
            const LongVector& d = ray.direction;
            const Long t = (point - ray.origin).dot(d) / d.squaredNorm();
            out.tangencies.push_back({t, (ray.at(t) - point).norm(), 0});
        }
    }
};

/// A reference shape seen through an affine map: the world ray is mapped into the object's
/// space in long double by the exact inverse of world_from_object (as stored in double).
class TransformedShape final : public ReferenceShape {
public:
    TransformedShape(std::shared_ptr<const ReferenceShape> shape, const Eigen::Matrix3d& linear,
                     const Vector3& translation)
        : shape_(std::move(shape)),
          inverse_(linear.cast<Long>().inverse()),
          translation_(translation.cast<Long>()) {}

    void crossings(const LongRay& ray, LineCrossings& out) const override {
        const LongRay local{inverse_ * (ray.origin - translation_), inverse_ * ray.direction};
        shape_->crossings(local, out);
    }

private:
    std::shared_ptr<const ReferenceShape> shape_;
    LongMatrix inverse_;
    LongVector translation_;
};

// ----- The shapes of core/, from their documented parameters -------------------------------

inline LongVector to_long(const Vector3& v) {
    return v.cast<Long>();
}

inline std::shared_ptr<PatchShape> reference_plane(const Point3& point, const Normal3& normal) {
    auto shape = std::make_shared<PatchShape>();
    shape->planes.push_back({to_long(point), to_long(normal).normalized(), nullptr});
    return shape;
}

inline std::shared_ptr<PatchShape> reference_triangle(const Point3& p0, const Point3& p1,
                                                      const Point3& p2) {
    const LongVector a = to_long(p0), b = to_long(p1), c = to_long(p2);
    const LongVector normal = (b - a).cross(c - a).normalized();
    auto shape = std::make_shared<PatchShape>();
    shape->planes.push_back({a, normal, [=](const LongVector& local) {
                                 const LongVector p = a + local;
                                 const LongVector corners[3] = {a, b, c};
                                 Long trim = kLongInfinity;
                                 for (int k = 0; k < 3; ++k) {
                                     const LongVector edge = corners[(k + 1) % 3] - corners[k];
                                     const LongVector cross = edge.cross(p - corners[k]);
                                     const Long distance = cross.norm() / edge.norm();
                                     trim = std::min(trim,
                                                     cross.dot(normal) >= 0 ? distance : -distance);
                                 }
                                 return trim;
                             }});
    return shape;
}

inline std::shared_ptr<PatchShape> reference_disk(const Point3& center, const Normal3& normal,
                                                  double radius) {
    auto shape = std::make_shared<PatchShape>();
    const Long r = radius;
    shape->planes.push_back({to_long(center), to_long(normal).normalized(),
                             [=](const LongVector& local) { return r - local.norm(); }});
    return shape;
}

inline std::shared_ptr<PatchShape> reference_rectangle(const Point3& corner, const Vector3& edge_a,
                                                       const Vector3& edge_b) {
    const LongVector a = to_long(edge_a), b = to_long(edge_b);
    const LongVector n = a.cross(b);
    const LongVector dual_a = b.cross(n) / a.dot(b.cross(n));
    const LongVector dual_b = n.cross(a) / b.dot(n.cross(a));
    // Heights of the parallelogram: the distance between the edges s = 0 and s = 1, and t.
    const Long height_a = n.norm() / b.norm(), height_b = n.norm() / a.norm();
    auto shape = std::make_shared<PatchShape>();
    shape->planes.push_back(
        {to_long(corner), n.normalized(), [=](const LongVector& local) {
             const Long s = local.dot(dual_a), t = local.dot(dual_b);
             return std::min({s * height_a, (1 - s) * height_a, t * height_b, (1 - t) * height_b});
         }});
    return shape;
}

/// Annulus in its frame (the shape's own frame axes, a convention rather than geometry).
inline std::shared_ptr<PatchShape> reference_annulus(const Point3& center, const Normal3& normal,
                                                     const Vector3& x_axis, const Vector3& z_axis,
                                                     double inner, double outer, double phi_min,
                                                     double phi_max) {
    const LongVector x = to_long(x_axis), z = to_long(z_axis);
    auto shape = std::make_shared<PatchShape>();
    shape->planes.push_back(
        {to_long(center), to_long(normal).normalized(), [=](const LongVector& local) {
             const Long rho = local.norm();
             Long trim = std::min(outer - rho, rho - inner);
             if (rho > 0) {
                 trim = std::min(
                     trim, angle_trim(azimuth(local.dot(x), local.dot(z)), phi_min, phi_max, rho));
             }
             return trim;
         }});
    return shape;
}

inline std::shared_ptr<PatchShape> reference_box(const Point3& lower, const Point3& upper) {
    auto shape = std::make_shared<PatchShape>();
    const LongVector lo = to_long(lower), hi = to_long(upper);
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
            LongVector point = side ? hi : lo;
            LongVector normal = LongVector::Zero();
            normal[axis] = side ? 1 : -1;
            shape->planes.push_back({point, normal, [=](const LongVector& local) {
                                         const LongVector p = point + local;
                                         Long trim = kLongInfinity;
                                         for (int k = 0; k < 3; ++k) {
                                             if (k == axis) continue;
                                             trim = std::min({trim, p[k] - lo[k], hi[k] - p[k]});
                                         }
                                         return trim;
                                     }});
        }
    }
    return shape;
}

inline QuadricPatch sphere_patch(const Point3& center, double radius, Trim trim = nullptr) {
    const Long r = radius;
    return {to_long(center), LongVector(1, 1, 1), LongVector::Zero(), -r * r, std::move(trim)};
}

inline std::shared_ptr<PatchShape> reference_sphere(const Point3& center, double radius) {
    auto shape = std::make_shared<PatchShape>();
    shape->quadrics.push_back(sphere_patch(center, radius));
    return shape;
}

inline std::shared_ptr<PatchShape> reference_part_sphere(const Point3& center, double radius,
                                                         double phi_min, double phi_max,
                                                         double theta_min, double theta_max) {
    const Long r = radius;
    // Polar limits as heights, y = r cos(theta); none at the poles.
    const Long y_high = theta_min == 0.0 ? kLongInfinity : r * std::cos(Long(theta_min));
    const Long y_low = theta_max == kPi ? -kLongInfinity : r * std::cos(Long(theta_max));
    auto shape = std::make_shared<PatchShape>();
    shape->quadrics.push_back(sphere_patch(center, radius, [=](const LongVector& x) {
        const Long rho = std::sqrt(x.x() * x.x() + x.z() * x.z());
        Long trim = std::min(x.y() - y_low, y_high - x.y());
        if (rho > 0)
            trim = std::min(trim, angle_trim(azimuth(x.x(), x.z()), phi_min, phi_max, rho));
        return trim;
    }));
    return shape;
}

inline QuadricPatch cylinder_side(double radius, Trim trim) {
    const Long r = radius;
    return {LongVector::Zero(), LongVector(1, 0, 1), LongVector::Zero(), -r * r, std::move(trim)};
}

/// A cap of a shape of revolution: the disk of `radius` in the plane y = height.
inline PlanePatch cap(double height, double radius, bool up) {
    const Long r = radius;
    return {LongVector(0, height, 0), LongVector(0, up ? 1 : -1, 0),
            [=](const LongVector& local) { return r - local.norm(); }};
}

inline std::shared_ptr<PatchShape> reference_cylinder(double radius, double y_min, double y_max,
                                                      bool capped) {
    auto shape = std::make_shared<PatchShape>();
    const Long lo = y_min, hi = y_max;
    shape->quadrics.push_back(cylinder_side(
        radius, [=](const LongVector& x) { return std::min(x.y() - lo, hi - x.y()); }));
    if (capped) {
        shape->planes.push_back(cap(y_min, radius, false));
        shape->planes.push_back(cap(y_max, radius, true));
    }
    return shape;
}

inline std::shared_ptr<PatchShape> reference_part_cylinder(double radius, double y_min,
                                                           double y_max, double phi_min,
                                                           double phi_max) {
    auto shape = std::make_shared<PatchShape>();
    const Long lo = y_min, hi = y_max, r = radius;
    shape->quadrics.push_back(cylinder_side(radius, [=](const LongVector& x) {
        return std::min(
            {x.y() - lo, hi - x.y(), angle_trim(azimuth(x.x(), x.z()), phi_min, phi_max, r)});
    }));
    return shape;
}

/// x^2 + z^2 = rho(y)^2 with rho(y) = base + k y, for y in [0, height]: there rho >= 0, so the
/// trim also removes the other nappe.
inline std::shared_ptr<PatchShape> reference_cone(double base, double top, double height,
                                                  bool capped) {
    const Long k = (Long(top) - Long(base)) / Long(height);
    const Long b = base, h = height;
    auto shape = std::make_shared<PatchShape>();
    shape->quadrics.push_back({LongVector::Zero(), LongVector(1, -k * k, 1),
                               LongVector(0, -b * k, 0), -b * b,
                               [=](const LongVector& x) { return std::min(x.y(), h - x.y()); }});
    if (capped && base > 0) shape->planes.push_back(cap(0.0, base, false));
    if (capped && top > 0) shape->planes.push_back(cap(height, top, true));
    if (base == 0.0) shape->singular_points.push_back(LongVector(0, 0, 0));
    if (top == 0.0) shape->singular_points.push_back(LongVector(0, h, 0));
    return shape;
}

inline std::shared_ptr<PatchShape> reference_torus(double major, double minor) {
    auto shape = std::make_shared<PatchShape>();
    shape->tori.push_back({major, minor, nullptr});
    return shape;
}

inline std::shared_ptr<PatchShape> reference_part_torus(double major, double minor, double phi_min,
                                                        double phi_max, double theta_min,
                                                        double theta_max) {
    const Long big = major, small = minor;
    auto shape = std::make_shared<PatchShape>();
    shape->tori.push_back({major, minor, [=](const LongVector& p) {
                               const Long rho = std::sqrt(p.x() * p.x() + p.z() * p.z());
                               const Long phi = azimuth(p.x(), p.z());
                               const Long theta = azimuth(p.y(), rho - big);
                               return std::min(angle_trim(phi, phi_min, phi_max, rho),
                                               angle_trim(theta, theta_min, theta_max, small));
                           }});
    return shape;
}

}  // namespace csgrt::test
