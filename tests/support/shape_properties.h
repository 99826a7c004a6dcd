#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <functional>
#include <string>

#include "csgrt/core/math.h"
#include "csgrt/core/shape.h"
#include "support/random.h"

namespace csgrt::test {

/// An independent description of a shape's surface for property tests: an implicit function
/// that is zero on the surface, and its gradient. (Part objects check their limits in their
/// own tests.)
struct SurfaceDescription {
    std::function<double(const Point3&)> value;
    std::function<Vector3(const Point3&)> gradient;
    /// The shape's size (a radius, a half extent): distances are judged relative to it.
    double scale = 1.0;
    /// Where rays start and aim: usually the bounds.
    Aabb region;
};

/// The plane through `anchor` with unit normal `normal` as the zero set of (p - a) . n, of size
/// `scale`, rays aimed at `region`: any flat shape's surface.
inline SurfaceDescription plane_surface(const Point3& anchor, const Normal3& normal, double scale,
                                        const Aabb& region) {
    return {[anchor, normal](const Point3& p) { return (p - anchor).dot(normal); },
            [normal](const Point3&) { return Vector3(normal); }, scale, region};
}

/// The sphere of `center` and `radius` as the zero set of |p - c|^2 - r^2, rays aimed at `region`.
inline SurfaceDescription sphere_surface(const Point3& center, double radius, const Aabb& region) {
    return {
        [center, radius](const Point3& p) { return (p - center).squaredNorm() - square(radius); },
        [center](const Point3& p) { return Vector3(2.0 * (p - center)); }, radius, region};
}

/// The torus of `major` radius R and `minor` radius r about the y axis as the zero set of its
/// quartic (|p|^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + z^2), evaluated in double; rays aimed at `region`.
inline SurfaceDescription torus_surface(double major, double minor, const Aabb& region) {
    return {[major, minor](const Point3& p) {
                return square(p.squaredNorm() + major * major - minor * minor) -
                       4 * major * major * (p.x() * p.x() + p.z() * p.z());
            },
            [major, minor](const Point3& p) {
                const double k = 4 * (p.squaredNorm() + major * major - minor * minor);
                return Vector3(k * p.x() - 8 * major * major * p.x(), k * p.y(),
                               k * p.z() - 8 * major * major * p.z());
            },
            minor, region};
}

/// The tolerances of a property check, in units of the double unit roundoff u = 2^-53 times the
/// magnitudes involved, so they scale with the coordinates instead of being absolute.
struct PropertyTolerance {
    /// A hit point may be off the surface by distance_ulps * u * (|o| + |t d| + scale): the
    /// rounding of o + t d plus the error of the root, a few ulps for closed forms.
    double distance_ulps = 64.0;
    /// Normals may deviate from the gradient direction by this angle (radians); a point off
    /// the surface by e changes the normal by about e / scale.
    double normal_angle = 1e-9;
};

/// The tolerance of torus_surface. Near the surface the quartic's own rounding is about
/// 12 u (2 R rho)^2 (two terms of that size cancel) and its gradient has length 8 R rho r, so it
/// reports a point on the surface as up to 12 u 4 R^2 rho^2 / (8 R rho r) = 6 u R rho / r
/// <= 6 u R (R + r) / r away. The check allows distance_ulps u (|o| + |t d| + scale) with
/// |o| + |t d| >= R - r, so distance_ulps = 6 R (R + r) / (r (R - r)) + 16 (the projected hit
/// point's own few ulps) covers it.
inline PropertyTolerance torus_tolerance(double major, double minor) {
    PropertyTolerance tolerance;
    tolerance.distance_ulps = 6 * major * (major + minor) / (minor * (major - minor)) + 16;
    return tolerance;
}

/// Summary of one property run, so a test can assert how many rays actually hit.
struct PropertyCounts {
    int rays = 0;
    int hits = 0;
    int span_checks = 0;
};

/// Checks, on `rays` seeded random rays, that: a hit lies on the surface; its normal is unit
/// length and parallel to the gradient; `occluded` agrees with `intersect`; and, for solids,
/// that the first span boundary in [t_min, t_max] equals the hit's t and that `contains`
/// agrees with span membership at sample points away from the boundaries.
inline PropertyCounts check_shape_properties(const Shape& shape, const SurfaceDescription& surface,
                                             int rays, std::uint64_t seed,
                                             PropertyTolerance tolerance = {}) {
    Random random(seed);
    PropertyCounts counts;
    const Aabb from = enlarged(surface.region, 1.0);
    const Aabb toward = enlarged(surface.region, 0.05);
    int failures = 0;
    for (int i = 0; i < rays && failures < 10; ++i) {
        Ray ray = random.ray_between(from, toward);
        // Every fifth ray starts inside the region (possibly inside the solid).
        if (i % 5 == 0) ray.origin = random.in_box(surface.region);
        ++counts.rays;
        const std::optional<Hit> hit = shape.intersect(ray);
        const bool occluded = shape.occluded(ray);
        EXPECT_EQ(occluded, hit.has_value()) << "ray " << i << " seed " << seed;
        if (occluded != hit.has_value()) ++failures;
        if (hit) {
            ++counts.hits;
            const double magnitude =
                ray.origin.norm() + std::abs(hit->t) * ray.direction.norm() + surface.scale;
            const double allowed = tolerance.distance_ulps * kUnitRoundoff * magnitude;
            const Vector3 gradient = surface.gradient(hit->point);
            const double distance = std::abs(surface.value(hit->point)) / gradient.norm();
            EXPECT_LE(distance, allowed) << "hit off the surface, ray " << i << " seed " << seed;
            EXPECT_NEAR(hit->geometric_normal.norm(), 1.0, 8 * kUnitRoundoff) << "ray " << i;
            const double sine = hit->geometric_normal.cross(gradient.normalized()).norm();
            EXPECT_LE(sine, tolerance.normal_angle) << "normal not along gradient, ray " << i;
            EXPECT_TRUE(ray.in_range(hit->t)) << "ray " << i;
            if (distance > allowed || sine > tolerance.normal_angle) ++failures;
        }
        if (!shape.is_solid()) continue;
        const SpanList spans = shape.spans(ray);
        double first = kInfinity;
        for (const Span& span : spans) {
            if (span.enter.shape && ray.in_range(span.enter.t))
                first = std::min(first, span.enter.t);
            if (span.exit.shape && ray.in_range(span.exit.t)) first = std::min(first, span.exit.t);
        }
        if (hit) {
            const double allowed = tolerance.distance_ulps * kUnitRoundoff *
                                   (std::abs(hit->t) + surface.scale / ray.direction.norm());
            EXPECT_NEAR(first, hit->t, allowed) << "first span boundary, ray " << i;
        } else {
            EXPECT_EQ(first, kInfinity) << "spans in range but no hit, ray " << i;
        }
        // Point membership at sample points along the ray, away from span boundaries.
        const double margin = 1e-6 * surface.scale / ray.direction.norm();
        for (int sample = 0; sample < 4; ++sample) {
            const double t =
                random.uniform(0.0, 3.0 * (from.diagonal().norm() / ray.direction.norm()));
            bool inside = false;
            bool near_boundary = false;
            for (const Span& span : spans) {
                if (t > span.enter.t && t < span.exit.t) inside = true;
                if (std::abs(t - span.enter.t) < margin || std::abs(t - span.exit.t) < margin)
                    near_boundary = true;
            }
            if (near_boundary) continue;
            ++counts.span_checks;
            const bool contained = shape.contains(ray.at(t));
            EXPECT_EQ(contained, inside) << "contains vs spans at t=" << t << ", ray " << i;
            if (contained != inside) ++failures;
        }
    }
    return counts;
}

}  // namespace csgrt::test
