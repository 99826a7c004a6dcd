#pragma once

#include <gtest/gtest.h>

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
