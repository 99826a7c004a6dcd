#pragma once

#include <cstdint>
#include <optional>

#include "csgrt/core/math.h"
#include "csgrt/csg/scene.h"

namespace csgrt {

/// One shadow-ray's worth of a light, as seen from a surface point (docs/rendering.md, Lights).
struct LightSample {
    /// Unit direction from the point toward the sample.
    Vector3 to_light;
    /// Irradiance this sample brings on a surface facing it head on, already divided by the
    /// light's sample count: the sum over the samples estimates the light's irradiance, times
    /// the cosine at the receiver.
    Vector3 irradiance;
    /// The point sampled on the light, or nothing for a directional light (shadow rays then
    /// run to infinity).
    std::optional<Point3> position;
};

/// How many shadow rays `light` takes per shaded point: 1 for point and directional lights,
/// the light's `samples` for area lights.
int light_sample_count(const Light& light);

/// Sample `u` (in [0, 1)^2, a stratum's point: render/sampling.h) of `light` as seen from
/// `point`, or nothing when that part of the light sends nothing there (it faces away, or the
/// point is inside a sphere light). Rectangles map u linearly onto their area, disks by
/// Shirley and Chiu's concentric map ("A Low Distortion Map Between Disk and Square", 1997),
/// both of which keep strata equal in area; spheres by the cone of directions they subtend
/// (pbrt, 4th ed., 6.2.4), uniform in solid angle.
std::optional<LightSample> sample_light(const Light& light, const Point3& point, const Vector2& u);

/// The seed of the light samples at a surface point: a hash of its coordinates' bits, the
/// render's seed and the light's index, so the samples depend on nothing but the point (the
/// same whatever thread shades it, in whatever order) and differ from light to light.
std::uint64_t light_sample_seed(const Point3& point, std::uint64_t seed, std::size_t light);

}  // namespace csgrt
