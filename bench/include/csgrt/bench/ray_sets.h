#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "csgrt/core/aabb.h"
#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"
#include "csgrt/csg/camera.h"
#include "csgrt/render/sampling.h"

namespace csgrt::bench {

/// Seeded random numbers that are the same on every platform (SampleRandom's SplitMix64), so a
/// ray set is fixed by its seed alone, unlike the standard distributions, whose algorithms
/// vary; with the ranges, directions and points ray sets draw.
class SplitMix : public SampleRandom {
public:
    using SampleRandom::SampleRandom;
    using SampleRandom::uniform;

    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    /// Uniform on the unit sphere (Archimedes: z uniform in [-1, 1], azimuth uniform).
    Vector3 unit_vector() {
        const double z = uniform(-1.0, 1.0);
        const double azimuth = uniform(0.0, 2.0 * kPi);
        const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
        return {rho * std::cos(azimuth), rho * std::sin(azimuth), z};
    }
    Point3 in_box(const Aabb& box) {
        return {uniform(box.lower.x(), box.upper.x()), uniform(box.lower.y(), box.upper.y()),
                uniform(box.lower.z(), box.upper.z())};
    }
};

/// A named, fixed list of rays; camera rays also keep the image size (row-major pixels).
struct RaySet {
    std::string name;
    std::vector<Ray> rays;
    int width = 0;
    int height = 0;
};

/// A pinhole camera (40 degree vertical field of view) looking at the box's centre from the
/// direction `view` (from the centre toward the camera), far enough that a sphere of the box's
/// largest extent in diameter fills the view's height: the mesh fills much of the image.
inline Camera framing_camera(const Aabb& box, const Vector3& view = Vector3(0.3, 0.25, 1.0)) {
    Camera camera;
    camera.vertical_fov_degrees = 40.0;
    const double radius = 0.5 * box.diagonal().maxCoeff();
    const double distance = radius / std::sin(0.5 * camera.vertical_fov_degrees * kPi / 180.0);
    camera.look_at = box.center();
    camera.position = box.center() + distance * view.normalized();
    camera.up = Vector3(0.0, 1.0, 0.0);
    return camera;
}

/// One ray through the centre of each pixel of a width x height image, row by row, unit
/// directions, interval [0, inf).
inline RaySet camera_rays(const Camera& camera, int width, int height) {
    RaySet set{"camera", {}, width, height};
    set.rays.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    const double aspect = static_cast<double>(width) / height;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            set.rays.push_back(camera.generate_ray((x + 0.5) / width, (y + 0.5) / height, aspect));
        }
    }
    return set;
}

/// `count` incoherent rays: origins uniform on the sphere around the box (centre its centre,
/// radius 1.5 times its half diagonal), each aimed at a uniform random point of the box; unit
/// directions, interval [0, inf).
inline RaySet incoherent_rays(const Aabb& box, std::size_t count, std::uint64_t seed) {
    RaySet set{"incoherent", {}, 0, 0};
    set.rays.reserve(count);
    SplitMix random(seed);
    const double radius = 0.75 * box.diagonal().norm();
    while (set.rays.size() < count) {
        Ray ray;
        ray.origin = box.center() + radius * random.unit_vector();
        const Vector3 direction = random.in_box(box) - ray.origin;
        if (direction.squaredNorm() == 0.0) continue;
        ray.direction = direction.normalized();
        set.rays.push_back(ray);
    }
    return set;
}

/// What a primary ray found: the parameter t of its hit and the unit geometric normal there.
struct SurfaceHit {
    bool hit = false;
    double t = 0.0;
    Vector3 normal{0.0, 0.0, 1.0};
};

/// A point light above and to the left of the box, three bounding radii from its centre.
inline Point3 default_light(const Aabb& box) {
    return box.center() + 1.5 * box.diagonal().norm() * Vector3(-0.5, 1.0, 0.6).normalized();
}

/// Shadow (occlusion) rays toward `light` from the hit points of `primary`: for every hit
/// whose surface faces the light on the side the primary ray came from, a ray from the hit
/// point moved `offset` off the surface (along the normal, on that side) to the light, with
/// t in [0, 1] (the light is at t = 1). Hits the light cannot reach through their own surface
/// (N.L <= 0) are shadowed by definition and get no ray, as in a renderer.
inline RaySet shadow_rays(std::span<const Ray> primary, std::span<const SurfaceHit> hits,
                          const Point3& light, double offset) {
    RaySet set{"shadow", {}, 0, 0};
    for (std::size_t i = 0; i < primary.size() && i < hits.size(); ++i) {
        if (!hits[i].hit) continue;
        const Point3 point = primary[i].at(hits[i].t);
        // The normal on the side the primary ray arrived from.
        const Vector3 normal =
            primary[i].direction.dot(hits[i].normal) > 0.0 ? -hits[i].normal : hits[i].normal;
        if (normal.dot(light - point) <= 0.0) continue;
        Ray ray;
        ray.origin = point + offset * normal;
        ray.direction = light - ray.origin;
        ray.t_min = 0.0;
        ray.t_max = 1.0;
        set.rays.push_back(ray);
    }
    return set;
}

/// `count` rays of `rays` evenly spread over the list (all of them if there are fewer), so a
/// subset of camera rays covers the whole image rather than its top rows.
inline std::vector<Ray> spread_subset(std::span<const Ray> rays, std::size_t count) {
    if (count >= rays.size()) return {rays.begin(), rays.end()};
    std::vector<Ray> subset;
    subset.reserve(count);
    for (std::size_t k = 0; k < count; ++k) subset.push_back(rays[k * rays.size() / count]);
    return subset;
}

}  // namespace csgrt::bench
