#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/core/query_cost.h"

#include "csgrt/render/image.h"

namespace csgrt {

class Scene;

/// What `render` is asked to do.
struct RenderSettings {
    int width = 640;
    int height = 480;
    /// Colour samples per pixel, on a stratified jittered grid (sampling.h). One sample is
    /// taken at the pixel centre, unjittered.
    int samples_per_pixel = 1;
    /// Worker threads; 0 lets oneTBB use every core. A positive count also caps oneTBB's
    /// process-wide parallelism while the render runs. The image does not depend on it.
    int threads = 0;
    /// Pixels per side of the square tiles handed to the threads.
    int tile_size = 16;
    /// Seeds the per-pixel sample streams.
    std::uint64_t seed = 0;
    /// Most bounces of mirror and glass rays (0: camera and shadow rays only); a ray that
    /// would go deeper brings back black.
    int max_depth = 5;
    /// Linear radiance of rays that hit nothing. Camera samples that miss still count as
    /// uncovered (alpha 0), so a non-black background is added to colour as emission.
    Vector3 background{0.0, 0.0, 0.0};
    /// Radiance arriving at every surface from every direction, unshadowed: adds
    /// albedo * ambient to each opaque surface (the ambient term of classic renderers).
    Vector3 ambient{0.0, 0.0, 0.0};
    /// Called from worker threads after each finished tile with the fraction done; must be
    /// thread-safe and cheap. May be empty.
    std::function<void(double fraction_done)> progress;
};

/// Largest width or height `render` accepts, the most samples per pixel and bounces.
inline constexpr int kMaxImageSize = 16384;
inline constexpr int kMaxSamplesPerPixel = 4096;
inline constexpr int kMaxTraceDepth = 64;

/// What a render did.
struct RenderStats {
    /// Camera rays: the colour samples plus, when samples_per_pixel > 1, the centre ray that
    /// feeds the AOVs.
    std::uint64_t primary_rays = 0;
    std::uint64_t shadow_rays = 0;
    /// Mirror reflection and glass reflection and refraction rays.
    std::uint64_t secondary_rays = 0;
    /// Shadow rays that found something between the surface and the light.
    std::uint64_t shadow_rays_blocked = 0;
    /// Camera rays that hit an object (colour samples and the separate centre rays).
    std::uint64_t primary_hits = 0;
    /// Camera-ray hits per top-level object, indexed by object id.
    std::vector<std::uint64_t> hits_per_object;
    /// The top-level structure's work for the centre rays, summed over the image: nodes or
    /// cells visited, primitives tested, boxes tested.
    TraversalCounters centre_ray_work;
    /// The centre rays' work at every level (structures inside meshes and compounds, CSG
    /// nodes, leaf solves), summed over the image: the cost channels' sums.
    QueryCost centre_ray_cost;
    /// The centre rays' root solves by the leaf's kind() (their sum is centre_ray_cost.solves).
    std::map<std::string, std::uint64_t> solves_by_kind;
    /// Camera-ray hits by the kind() of the leaf hit ("mesh" for a mesh's triangles).
    std::map<std::string, std::uint64_t> hits_by_leaf_kind;
    double seconds = 0.0;

    double million_rays_per_second() const {
        return seconds > 0.0
                   ? 1e-6 * static_cast<double>(primary_rays + shadow_rays + secondary_rays) /
                         seconds
                   : 0.0;
    }
};

/// The result of `render`: the image and what it cost.
struct RenderResult {
    Image image;
    RenderStats stats;
};

/// Renders a committed scene through its camera (docs/rendering.md):
/// - primary rays through a stratified jittered grid of samples_per_pixel points per pixel;
/// - Lambert shading, radiance = albedo / pi * sum over lights of E cos(theta), with
///   E = intensity / distance^2 for point lights and E = radiance for directional ones, each
///   light tested with one hard shadow ray (Scene::occluded) from an offset origin;
/// - a scene without lights is lit from the eye instead: radiance = albedo |n . v|, and no
///   shadow rays are cast;
/// - the AOVs (depth, normal, object id, cost) from one ray through the pixel centre, its work
///   counted at every level of the scene (core/query_cost.h).
/// Tiles are rendered in parallel with oneTBB; the image is the same for any thread count.
/// Throws InvalidParameter for an uncommitted scene, an invalid camera, or a width, height or
/// sample count outside [1, kMaxImageSize] / [1, kMaxSamplesPerPixel].
RenderResult render(const Scene& scene, const RenderSettings& settings);

/// The cost channels alone (no shading, no other ray): one centre ray per pixel, counted
/// exactly as `render` counts it, in parallel like `render`. The layer's structure name and
/// build time are left for the caller. Throws what `render` throws.
CostLayer render_cost(const Scene& scene, const RenderSettings& settings);

/// Throws InvalidParameter naming the setting unless `settings` is one `render` accepts.
void validate(const RenderSettings& settings);

}  // namespace csgrt
