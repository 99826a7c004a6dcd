#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <optional>
#include <vector>

#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"
#include "csgrt/core/shape.h"

namespace csgrt::test {

/// The forward error bound of a flat shape's plane solve t = ((a - o) . n) / (d . n) (anchor a,
/// unit normal n, ray o + t d, all exact in long double) at the true `t`: each term of both dot
/// products carries at most 5 roundings (subtraction, product, sums, division) relative to its
/// magnitude, so gamma(6) of the terms' magnitudes over |d . n| bounds it.
template <class Vector>
long double plane_solve_bound(const Vector& a, const Vector& o, const Vector& d, const Vector& n,
                              long double t) {
    const long double magnitude = ((a.cwiseAbs() + o.cwiseAbs()).dot(n.cwiseAbs()) +
                                   std::abs(t) * d.cwiseAbs().dot(n.cwiseAbs())) /
                                  std::abs(d.dot(n));
    return gamma(6) * magnitude;
}

/// A flat shape's plane solve done in long double from its double inputs (anchor a, unit normal
/// n, ray o + t d): t = ((a - o) . n) / (d . n), the reference the double solve is held to.
struct LongPlaneSolve {
    using Vector = Eigen::Matrix<long double, 3, 1>;
    Vector a, n, o, d;
    long double t = 0;

    /// The point of the line at t, relative to the anchor.
    Vector offset() const { return o + t * d - a; }
    /// plane_solve_bound at t: how far from t the double solve may land.
    long double bound() const { return plane_solve_bound(a, o, d, n, t); }
};

/// The LongPlaneSolve of `ray` against the plane through `anchor` with unit normal `normal`.
inline LongPlaneSolve long_plane_solve(const Point3& anchor, const Normal3& normal,
                                       const Ray& ray) {
    LongPlaneSolve solve{anchor.cast<long double>(), normal.cast<long double>(),
                         ray.origin.cast<long double>(), ray.direction.cast<long double>()};
    solve.t = (solve.a - solve.o).dot(solve.n) / solve.d.dot(solve.n);
    return solve;
}

/// A hit's t against a reference t, as a distance along the ray relative to the magnitudes
/// involved: |t - t_ref| |d| / (|o| + |t d| + size) (about half the relative t error when
/// |o| ~ |t d|). Moving the origin along the line costs a rounding of about 2 u |o| per
/// coordinate, which shifts the hit along the ray by that much over the cosine between ray and
/// normal; the roots and the final addition add a few ulps. Hence the bound (16 / cos + 8) u.
struct AlongRayError {
    double error = 0.0;
    /// |cos| of the angle between the ray and the normal of the surface actually hit (a ray
    /// aimed at one surface may meet another first).
    double cosine = 0.0;

    /// (16 / cos + 8) u, the cosine taken as at least 1e-3.
    double bound() const { return kUnitRoundoff * (16.0 / std::max(cosine, 1e-3) + 8.0); }
    /// The error times the cosine, in units of u: what the accuracy tests print as their worst.
    double scaled() const { return error * std::max(cosine, 1e-3) / kUnitRoundoff; }
};

/// The AlongRayError of `hit` on `ray` against the reference t `expected`, for a shape `size`
/// across (its radius, or its largest dimension).
inline AlongRayError along_ray_error(const Ray& ray, const Hit& hit, long double expected,
                                     double size) {
    const double cosine = std::abs(ray.direction.normalized().dot(hit.geometric_normal));
    const double magnitude = ray.origin.norm() + std::abs(hit.t) * ray.direction.norm() + size;
    const double error =
        static_cast<double>(std::abs(hit.t - expected)) * ray.direction.norm() / magnitude;
    return {error, cosine};
}

/// Invalid versions of the valid ray `valid`: each origin and each direction component made NaN,
/// +inf and -inf in turn, a zero direction, a NaN t_min, a NaN t_max, and t_min 5 above t_max
/// 4. is_valid rejects each (checked here), so no query may report a hit.
inline std::vector<Ray> invalid_variants(const Ray& valid) {
    const double nan = std::nan("");
    const Point3 o = valid.origin;
    const Vector3 d = valid.direction;
    std::vector<Ray> rays;
    for (int axis = 0; axis < 3; ++axis) {
        for (const double bad : {nan, kInfinity, -kInfinity}) {
            Ray origin{o, d};
            origin.origin[axis] = bad;
            rays.push_back(origin);
            Ray direction{o, d};
            direction.direction[axis] = bad;
            rays.push_back(direction);
        }
    }
    rays.push_back(Ray{o, Vector3(0, 0, 0)});
    rays.push_back(Ray{o, d, nan, kInfinity});
    rays.push_back(Ray{o, d, 0.0, nan});
    rays.push_back(Ray{o, d, 5.0, 4.0});
    for (const Ray& ray : rays) EXPECT_FALSE(is_valid(ray));
    return rays;
}

/// The interval checks of a shape that `ray` crosses once, at t > 0: [.., t) misses, t_max = t
/// and t_min = t hit, (t, ..] misses; occluded agrees with intersect at each.
inline void expect_interval_honoured(const Shape& shape, const Ray& ray, double t) {
    Ray clipped = ray;
    clipped.t_max = std::nextafter(t, 0.0);
    EXPECT_FALSE(shape.intersect(clipped));
    EXPECT_FALSE(shape.occluded(clipped));
    clipped.t_max = t;
    EXPECT_TRUE(shape.intersect(clipped));
    EXPECT_TRUE(shape.occluded(clipped));
    clipped = ray;
    clipped.t_min = t;
    EXPECT_TRUE(shape.intersect(clipped));
    EXPECT_TRUE(shape.occluded(clipped));
    clipped.t_min = std::nextafter(t, 2.0 * t);
    EXPECT_FALSE(shape.intersect(clipped));
    EXPECT_FALSE(shape.occluded(clipped));
}

/// No query of `shape` reports anything for any invalid variant of the valid ray `valid`
/// (invalid_variants): no hit, no occlusion, no span.
inline void expect_invalid_rays_miss(const Shape& shape, const Ray& valid) {
    for (const Ray& ray : invalid_variants(valid)) {
        EXPECT_FALSE(shape.intersect(ray)) << shape.kind();
        EXPECT_FALSE(shape.occluded(ray)) << shape.kind();
        EXPECT_TRUE(shape.spans(ray).empty()) << shape.kind();
    }
}

/// Each of `rays` misses `shape`: no hit and no occlusion.
inline void expect_misses(const Shape& shape, std::initializer_list<Ray> rays) {
    for (const Ray& ray : rays) {
        EXPECT_FALSE(shape.intersect(ray)) << shape.kind();
        EXPECT_FALSE(shape.occluded(ray)) << shape.kind();
    }
}

/// `ray` meets `shape` from behind its surface at exactly `t`: the hit keeps the shape's own
/// geometric normal `normal` (not turned toward the ray) and says it is back-facing. Returns the
/// hit for further checks: empty, after a failure, when there is none.
inline std::optional<Hit> expect_hit_from_behind(const Shape& shape, const Ray& ray, double t,
                                                 const Normal3& normal) {
    const std::optional<Hit> hit = shape.intersect(ray);
    EXPECT_TRUE(hit) << shape.kind();
    if (!hit) return hit;
    EXPECT_EQ(hit->t, t) << shape.kind();
    EXPECT_EQ(hit->geometric_normal, normal) << shape.kind();
    EXPECT_FALSE(hit->front_face) << shape.kind();
    return hit;
}

/// `ray` starts on the surface of the flat (or otherwise once-crossed) `shape` and leaves it:
/// it hits at t = 0 exactly, and from t_min = 1e-12 on it meets nothing.
inline void expect_hit_only_at_start(const Shape& shape, Ray ray) {
    const std::optional<Hit> hit = shape.intersect(ray);
    ASSERT_TRUE(hit) << shape.kind();
    EXPECT_EQ(hit->t, 0.0) << shape.kind();
    ray.t_min = 1e-12;
    EXPECT_FALSE(shape.intersect(ray)) << shape.kind();
    EXPECT_FALSE(shape.occluded(ray)) << shape.kind();
}

}  // namespace csgrt::test
