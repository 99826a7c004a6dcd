#include "csgrt/render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <variant>

#include "csgrt/core/error.h"
#include "csgrt/csg/scene.h"
#include "csgrt/render/sampling.h"
#include "csgrt/render/shadow_offset.h"

namespace csgrt {

namespace {

/// Everything one pixel's rays need that does not change from pixel to pixel.
struct Frame {
    const Scene& scene;
    const RenderSettings& settings;
    CameraFilm film;
    StrataGrid strata;
};

Vector3 albedo_of(const Scene& scene, std::uint32_t object_id) {
    if (object_id >= scene.objects().size()) return Material{}.albedo;
    const std::uint32_t material = scene.objects()[object_id].material;
    if (material >= scene.materials().size()) return Material{}.albedo;
    return scene.materials()[material].albedo;
}

/// Linear radiance leaving `hit` toward the camera along `ray` (unit direction).
Vector3 shade(const Frame& frame, const Ray& ray, const Hit& hit, QueryScratch& scratch,
              std::uint64_t& shadow_rays) {
    const Vector3 albedo = albedo_of(frame.scene, hit.object_id);
    const Vector3 view = -ray.direction;
    // Both sides of every surface are shaded: turn the normals to the side the ray came from.
    Normal3 geometric = hit.geometric_normal;
    if (geometric.dot(view) < 0.0) geometric = -geometric;
    Normal3 shading = hit.shading_normal;
    if (shading.dot(geometric) < 0.0) shading = -shading;

    if (frame.scene.lights().empty()) {
        // An eye light: without it a scene without lights would render black.
        return albedo * std::abs(shading.dot(view));
    }

    // Sized by the precision of the surface hit, not by the scene's distance from the origin.
    const Point3 origin = spawn_ray_origin(hit, geometric);
    Vector3 radiance = Vector3::Zero();
    for (const Light& light : frame.scene.lights()) {
        Vector3 to_light;
        Vector3 irradiance;
        Ray shadow;
        shadow.origin = origin;
        if (const auto* point = std::get_if<PointLight>(&light)) {
            const Vector3 offset = point->position - hit.point;
            const double distance_squared = offset.squaredNorm();
            if (!(distance_squared > 0.0)) continue;
            to_light = offset / std::sqrt(distance_squared);
            irradiance = point->intensity / distance_squared;
            // Up to the light, stopping short of it by the same relative margin the origin
            // keeps from the surface, so a light lying on a surface is not hidden by it.
            shadow.direction = point->position - origin;
            shadow.t_max = 1.0 - kRayOffsetRelative;
        } else {
            const auto& directional = std::get<DirectionalLight>(light);
            to_light = -directional.direction.normalized();
            irradiance = directional.radiance;
            shadow.direction = to_light;
            shadow.t_max = kInfinity;
        }
        const double cosine = shading.dot(to_light);
        // A light behind the surface (by either normal) sends nothing and needs no shadow ray.
        if (!(cosine > 0.0) || !(geometric.dot(to_light) > 0.0)) continue;
        ++shadow_rays;
        if (frame.scene.occluded(shadow, scratch)) continue;
        radiance += albedo.cwiseProduct(irradiance) * (cosine / kPi);
    }
    return radiance;
}

void render_pixel(const Frame& frame, int x, int y, Pixel& pixel, QueryScratch& scratch,
                  std::uint64_t& shadow_rays) {
    const RenderSettings& settings = frame.settings;
    const double width = settings.width;
    const double height = settings.height;

    // The AOVs come from one counted ray through the pixel centre.
    const Ray centre = frame.film.ray((x + 0.5) / width, (y + 0.5) / height);
    TraversalCounters counters;
    const std::optional<Hit> centre_hit = frame.scene.intersect_counted(centre, scratch, counters);
    pixel.cost = static_cast<float>(counters.nodes_visited + counters.primitives_tested);
    if (centre_hit) {
        pixel.depth = static_cast<float>(centre_hit->t);
        pixel.normal_x = static_cast<float>(centre_hit->shading_normal.x());
        pixel.normal_y = static_cast<float>(centre_hit->shading_normal.y());
        pixel.normal_z = static_cast<float>(centre_hit->shading_normal.z());
        pixel.object_id = centre_hit->object_id;
    }

    Vector3 colour = Vector3::Zero();
    int covered = 0;
    if (settings.samples_per_pixel == 1) {
        if (centre_hit) {
            colour = shade(frame, centre, *centre_hit, scratch, shadow_rays);
            covered = 1;
        }
    } else {
        SampleRandom random = pixel_random(settings.seed, x, y);
        for (int sample = 0; sample < settings.samples_per_pixel; ++sample) {
            const Vector2 film = stratified_sample(frame.strata, sample, random);
            const Ray ray = frame.film.ray((x + film.x()) / width, (y + film.y()) / height);
            const std::optional<Hit> hit = frame.scene.intersect(ray, scratch);
            if (!hit) continue;
            colour += shade(frame, ray, *hit, scratch, shadow_rays);
            ++covered;
        }
    }
    const double weight = 1.0 / settings.samples_per_pixel;
    pixel.red = static_cast<float>(colour.x() * weight);
    pixel.green = static_cast<float>(colour.y() * weight);
    pixel.blue = static_cast<float>(colour.z() * weight);
    pixel.alpha = static_cast<float>(covered * weight);
}

}  // namespace

void validate(const RenderSettings& settings) {
    require(settings.width >= 1 && settings.width <= kMaxImageSize, "RenderSettings", "width",
            "in [1, " + std::to_string(kMaxImageSize) + "]", settings.width);
    require(settings.height >= 1 && settings.height <= kMaxImageSize, "RenderSettings", "height",
            "in [1, " + std::to_string(kMaxImageSize) + "]", settings.height);
    require(settings.samples_per_pixel >= 1 && settings.samples_per_pixel <= kMaxSamplesPerPixel,
            "RenderSettings", "samples_per_pixel",
            "in [1, " + std::to_string(kMaxSamplesPerPixel) + "]", settings.samples_per_pixel);
    require(settings.threads >= 0, "RenderSettings", "threads", ">= 0 (0: all cores)",
            settings.threads);
    require(settings.tile_size >= 1, "RenderSettings", "tile_size", ">= 1", settings.tile_size);
}

RenderResult render(const Scene& scene, const RenderSettings& settings) {
    validate(settings);
    require(scene.is_committed(), "render", "scene", "committed", "not committed");
    scene.camera().validate();

    const auto start = std::chrono::steady_clock::now();
    RenderResult result{Image(settings.width, settings.height), {}};
    const Frame frame{scene, settings,
                      CameraFilm(scene.camera(), double(settings.width) / settings.height),
                      strata_for(settings.samples_per_pixel)};

    const int tiles_x = (settings.width + settings.tile_size - 1) / settings.tile_size;
    const int tiles_y = (settings.height + settings.tile_size - 1) / settings.tile_size;
    const int tile_count = tiles_x * tiles_y;
    // One scratch per worker thread, reused across its tiles.
    tbb::enumerable_thread_specific<QueryScratch> scratches;
    std::atomic<std::uint64_t> shadow_rays{0};
    std::atomic<int> tiles_done{0};

    auto render_tiles = [&](const tbb::blocked_range<int>& range) {
        QueryScratch& scratch = scratches.local();
        for (int tile = range.begin(); tile != range.end(); ++tile) {
            const int x0 = (tile % tiles_x) * settings.tile_size;
            const int y0 = (tile / tiles_x) * settings.tile_size;
            const int x1 = std::min(x0 + settings.tile_size, settings.width);
            const int y1 = std::min(y0 + settings.tile_size, settings.height);
            std::uint64_t tile_shadow_rays = 0;
            for (int y = y0; y < y1; ++y) {
                for (int x = x0; x < x1; ++x) {
                    render_pixel(frame, x, y, result.image.at(x, y), scratch, tile_shadow_rays);
                }
            }
            shadow_rays += tile_shadow_rays;
            const int done = ++tiles_done;
            if (settings.progress) settings.progress(double(done) / tile_count);
        }
    };
    // An explicit thread count may exceed the cores: the global control lets oneTBB start that
    // many workers (the arena alone would be capped at the core count, with a warning).
    std::optional<tbb::global_control> parallelism;
    if (settings.threads > 0) {
        parallelism.emplace(tbb::global_control::max_allowed_parallelism, settings.threads);
    }
    tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
    arena.execute(
        [&] { tbb::parallel_for(tbb::blocked_range<int>(0, tile_count, 1), render_tiles); });

    const auto pixels = static_cast<std::uint64_t>(result.image.pixel_count());
    const auto samples = static_cast<std::uint64_t>(settings.samples_per_pixel);
    result.stats.primary_rays = pixels * samples + (samples > 1 ? pixels : 0);
    result.stats.shadow_rays = shadow_rays.load();
    result.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace csgrt
