#include "csgrt/render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "csgrt/core/error.h"
#include "csgrt/csg/scene.h"
#include "csgrt/render/lights.h"
#include "csgrt/render/materials.h"
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

/// What one worker counts for the statistics (RenderStats), summed when the render ends.
struct RayTally {
    std::uint64_t shadow_rays = 0;
    std::uint64_t shadow_rays_blocked = 0;
    std::uint64_t secondary_rays = 0;
    std::uint64_t primary_hits = 0;
    TraversalCounters centre_ray_work;
    QueryCost centre_ray_cost;
    /// Sized to the scene's objects once per worker, so counting allocates nothing per ray.
    std::vector<std::uint64_t> hits_per_object;
    /// Keyed by kind() literals; each grows once per kind met, not per ray.
    KindCounts hits_by_leaf_kind;
    KindCounts solves_by_kind;

    void count_hit(const Hit& hit) {
        ++primary_hits;
        if (hit.object_id < hits_per_object.size()) ++hits_per_object[hit.object_id];
        if (hit.shape != nullptr) hits_by_leaf_kind.add(hit.shape->kind());
    }
};

/// The material of the surface hit: the one a Painted shape on its path gave it (a CSG
/// operand's, csg/painted.h), else its scene object's.
const Material& material_of(const Scene& scene, const Hit& hit) {
    static const Material kDefault;
    std::uint32_t material = hit.material;
    if (material == kNoIndex) {
        if (hit.object_id >= scene.objects().size()) return kDefault;
        material = scene.objects()[hit.object_id].material;
    }
    if (material >= scene.materials().size()) return kDefault;
    return scene.materials()[material];
}

/// The scene's ambient radiance plus RenderSettings::ambient (docs/rendering.md: the two add).
Vector3 ambient_of(const Frame& frame) {
    return frame.scene.ambient() + frame.settings.ambient;
}

/// The radiance of rays that hit nothing: the scene's background plus RenderSettings::background.
Vector3 background_of(const Frame& frame) {
    return frame.scene.background() + frame.settings.background;
}

/// Linear radiance leaving `hit` toward the camera along `ray` (unit direction).
Vector3 shade(const Frame& frame, const Ray& ray, const Hit& hit, QueryScratch& scratch,
              RayTally& tally) {
    const Material& material = material_of(frame.scene, hit);
    const Vector3& albedo = material.albedo;
    const Vector3 view = -ray.direction;
    // Both sides of every surface are shaded: turn the normals to the side the ray came from.
    Normal3 geometric = hit.geometric_normal;
    if (geometric.dot(view) < 0.0) geometric = -geometric;
    Normal3 shading = hit.shading_normal;
    if (shading.dot(geometric) < 0.0) shading = -shading;

    if (frame.scene.lights().empty()) {
        // An eye light: without it a scene without lights would render black.
        return albedo * std::abs(shading.dot(view)) + albedo.cwiseProduct(ambient_of(frame));
    }

    // Sized by the precision of the surface hit, not by the scene's distance from the origin.
    const Point3 origin = spawn_ray_origin(hit, geometric);
    Vector3 radiance = albedo.cwiseProduct(ambient_of(frame));
    const std::vector<Light>& lights = frame.scene.lights();
    for (std::size_t index = 0; index < lights.size(); ++index) {
        const Light& light = lights[index];
        const int samples = light_sample_count(light);
        // Area lights: `samples` shadow rays, one per stratum of the light's area, jittered by
        // a stream that depends only on the point shaded (render/lights.h), so renders are
        // reproducible whatever the threads do.
        const StrataGrid strata = samples > 1 ? strata_for(samples) : StrataGrid{};
        SampleRandom random(samples > 1 ? light_sample_seed(hit.point, frame.settings.seed, index)
                                        : 0);
        for (int sample = 0; sample < samples; ++sample) {
            Vector3 to_light;
            Vector3 irradiance;
            Ray shadow;
            shadow.origin = origin;
            if (const auto* point = std::get_if<PointLight>(&light)) {
                const Vector3 offset = point->position - hit.point;
                const double distance_squared = offset.squaredNorm();
                if (!(distance_squared > 0.0)) continue;
                to_light = offset / std::sqrt(distance_squared);
                irradiance = point->falloff == 2.0
                                 ? Vector3(point->intensity / distance_squared)
                                 : Vector3(point->intensity /
                                           std::pow(distance_squared, 0.5 * point->falloff));
                // Up to the light, stopping short of it by the same relative margin the origin
                // keeps from the surface, so a light lying on a surface is not hidden by it.
                shadow.direction = point->position - origin;
                shadow.t_max = 1.0 - kRayOffsetRelative;
            } else if (const auto* directional = std::get_if<DirectionalLight>(&light)) {
                to_light = -directional->direction.normalized();
                irradiance = directional->radiance;
                shadow.direction = to_light;
                shadow.t_max = kInfinity;
            } else {
                const std::optional<LightSample> on_light =
                    sample_light(light, hit.point, stratified_sample(strata, sample, random));
                if (!on_light) continue;
                to_light = on_light->to_light;
                irradiance = on_light->irradiance;
                shadow.direction = *on_light->position - origin;
                shadow.t_max = 1.0 - kRayOffsetRelative;
            }
            const double cosine = shading.dot(to_light);
            // A light behind the surface (by either normal) sends nothing and needs no shadow
            // ray.
            if (!(cosine > 0.0) || !(geometric.dot(to_light) > 0.0)) continue;
            ++tally.shadow_rays;
            if (frame.scene.occluded(shadow, scratch)) {
                ++tally.shadow_rays_blocked;
                continue;
            }
            radiance += albedo.cwiseProduct(irradiance) * (cosine / kPi);
            if (material.specular.maxCoeff() > 0.0) {
                const double lobe = phong_lobe(to_light, view, shading, material.shininess);
                radiance += material.specular.cwiseProduct(irradiance) * (lobe * cosine);
            }
        }
    }
    return radiance;
}

Vector3 shade_surface(const Frame& frame, const Ray& ray, const Hit& hit, QueryScratch& scratch,
                      RayTally& tally, int depth);

/// Radiance arriving along a mirror or glass ray spawned at bounce `depth` (1 for the first).
Vector3 trace(const Frame& frame, const Ray& ray, QueryScratch& scratch, RayTally& tally,
              int depth) {
    if (depth > frame.settings.max_depth) return Vector3::Zero();
    ++tally.secondary_rays;
    const std::optional<Hit> hit = frame.scene.intersect(ray, scratch);
    if (!hit) return background_of(frame);
    return shade_surface(frame, ray, *hit, scratch, tally, depth);
}

/// A ray leaving hit.point along `direction`, on the side of `side` (the geometric normal
/// turned to that side), from the origin shadow rays use (spawn_ray_origin: sized by the
/// precision of the surface hit).
Ray spawned_ray(const Hit& hit, const Normal3& side, const Vector3& direction) {
    Ray ray;
    ray.origin = spawn_ray_origin(hit, side);
    ray.direction = direction;
    ray.t_max = kInfinity;
    return ray;
}

/// The radiance leaving `hit` along -ray.direction: glass (render/materials.h) by Fresnel
/// reflection and refraction; other materials by direct light (shade) plus mirror reflection.
Vector3 shade_surface(const Frame& frame, const Ray& ray, const Hit& hit, QueryScratch& scratch,
                      RayTally& tally, int depth) {
    const Material& material = material_of(frame.scene, hit);
    const Vector3& direction = ray.direction;
    if (material.ior > 0.0) {
        // The surface's own normal is outward (CSG results included), so its sign says whether
        // the ray enters or leaves the solid.
        const bool entering = direction.dot(hit.geometric_normal) < 0.0;
        const Normal3 geometric = entering ? hit.geometric_normal : -hit.geometric_normal;
        Normal3 normal = entering ? hit.shading_normal : -hit.shading_normal;
        if (normal.dot(geometric) < 0.0) normal = geometric;
        const double eta_incident = entering ? 1.0 : material.ior;
        const double eta_transmitted = entering ? material.ior : 1.0;
        const double reflectance =
            fresnel_dielectric(-direction.dot(normal), eta_incident, eta_transmitted);
        Vector3 radiance =
            reflectance * trace(frame, spawned_ray(hit, geometric, reflect(direction, normal)),
                                scratch, tally, depth + 1);
        if (reflectance < 1.0) {
            if (const auto refracted = refract(direction, normal, eta_incident / eta_transmitted)) {
                radiance +=
                    (1.0 - reflectance) * trace(frame, spawned_ray(hit, -geometric, *refracted),
                                                scratch, tally, depth + 1);
            }
        }
        return radiance;
    }
    Vector3 radiance = shade(frame, ray, hit, scratch, tally);
    if (material.mirror.maxCoeff() > 0.0 && depth < frame.settings.max_depth) {
        const Normal3 geometric = direction.dot(hit.geometric_normal) < 0.0 ? hit.geometric_normal
                                                                            : -hit.geometric_normal;
        Normal3 normal = hit.shading_normal;
        if (normal.dot(geometric) < 0.0) normal = -normal;
        radiance += material.mirror.cwiseProduct(
            trace(frame, spawned_ray(hit, geometric, reflect(direction, normal)), scratch, tally,
                  depth + 1));
    }
    return radiance;
}

/// The ray through the centre of pixel (x, y).
Ray centre_ray(const Frame& frame, int x, int y) {
    return frame.film.ray((x + 0.5) / frame.settings.width, (y + 0.5) / frame.settings.height);
}

/// `centre` (a centre_ray) traced with its work counted at every level: the top-level
/// structure's in `counters`, everything below it by a cost scope, summed into `cost`.
std::optional<Hit> trace_centre_ray(const Frame& frame, const Ray& centre, QueryScratch& scratch,
                                    TraversalCounters& counters, QueryCost& cost) {
    std::optional<Hit> hit;
    {
        const CostScope counting(scratch, cost);
        hit = frame.scene.intersect_counted(centre, scratch, counters);
    }
    cost.nodes += counters.nodes_visited;
    cost.primitives += counters.primitives_tested;
    return hit;
}

void render_pixel(const Frame& frame, int x, int y, Pixel& pixel, QueryScratch& scratch,
                  RayTally& tally) {
    const RenderSettings& settings = frame.settings;
    const double width = settings.width;
    const double height = settings.height;

    // The AOVs come from one ray through the pixel centre (with one sample, also its colour).
    const Ray centre = centre_ray(frame, x, y);
    // The image's memory holds nothing yet (Image::for_writing): the background's AOVs first.
    pixel = Pixel{};
    TraversalCounters counters;
    QueryCost cost;
    cost.solves_by_kind = &tally.solves_by_kind;
    const std::optional<Hit> centre_hit = trace_centre_ray(frame, centre, scratch, counters, cost);
    pixel.cost = static_cast<float>(cost.total());
    pixel.cost_nodes = static_cast<float>(cost.nodes);
    pixel.cost_primitives = static_cast<float>(cost.primitives);
    pixel.cost_solves = static_cast<float>(cost.solves);
    tally.centre_ray_cost += cost;
    tally.centre_ray_work.nodes_visited += counters.nodes_visited;
    tally.centre_ray_work.primitives_tested += counters.primitives_tested;
    tally.centre_ray_work.boxes_tested += counters.boxes_tested;
    if (centre_hit) {
        tally.count_hit(*centre_hit);
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
            colour = shade_surface(frame, centre, *centre_hit, scratch, tally, 0);
            covered = 1;
        } else {
            colour = background_of(frame);
        }
    } else {
        SampleRandom random = pixel_random(settings.seed, x, y);
        for (int sample = 0; sample < settings.samples_per_pixel; ++sample) {
            const Vector2 film = stratified_sample(frame.strata, sample, random);
            const Ray ray = frame.film.ray((x + film.x()) / width, (y + film.y()) / height);
            const std::optional<Hit> hit = frame.scene.intersect(ray, scratch);
            if (!hit) {
                colour += background_of(frame);
                continue;
            }
            tally.count_hit(*hit);
            colour += shade_surface(frame, ray, *hit, scratch, tally, 0);
            ++covered;
        }
    }
    const double weight = 1.0 / settings.samples_per_pixel;
    pixel.red = static_cast<float>(colour.x() * weight);
    pixel.green = static_cast<float>(colour.y() * weight);
    pixel.blue = static_cast<float>(colour.z() * weight);
    pixel.alpha = static_cast<float>(covered * weight);
}

/// Calls visit(x, y, scratch, worker) for every pixel, in 16 x 16 tiles handed to
/// settings.threads threads by oneTBB; each thread owns one QueryScratch and one `Worker` of
/// `workers`, reused across its tiles. Reports progress after each tile.
template <class Worker, class Visit>
void for_each_pixel(const RenderSettings& settings,
                    tbb::enumerable_thread_specific<Worker>& workers, Visit&& visit) {
    const int tiles_x = (settings.width + settings.tile_size - 1) / settings.tile_size;
    const int tiles_y = (settings.height + settings.tile_size - 1) / settings.tile_size;
    const int tile_count = tiles_x * tiles_y;
    tbb::enumerable_thread_specific<QueryScratch> scratches;
    std::atomic<int> tiles_done{0};
    auto render_tiles = [&](const tbb::blocked_range<int>& range) {
        QueryScratch& scratch = scratches.local();
        Worker& worker = workers.local();
        for (int tile = range.begin(); tile != range.end(); ++tile) {
            const int x0 = (tile % tiles_x) * settings.tile_size;
            const int y0 = (tile / tiles_x) * settings.tile_size;
            const int x1 = std::min(x0 + settings.tile_size, settings.width);
            const int y1 = std::min(y0 + settings.tile_size, settings.height);
            for (int y = y0; y < y1; ++y) {
                for (int x = x0; x < x1; ++x) visit(x, y, scratch, worker);
            }
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
    require(settings.max_depth >= 0 && settings.max_depth <= kMaxTraceDepth, "RenderSettings",
            "max_depth", "in [0, " + std::to_string(kMaxTraceDepth) + "]", settings.max_depth);
    require(settings.background.allFinite() && (settings.background.array() >= 0.0).all(),
            "RenderSettings", "background", "finite and >= 0", settings.background);
    require(settings.ambient.allFinite() && (settings.ambient.array() >= 0.0).all(),
            "RenderSettings", "ambient", "finite and >= 0", settings.ambient);
}

RenderResult render(const Scene& scene, const RenderSettings& settings) {
    validate(settings);
    require(scene.is_committed(), "render", "scene", "committed", "not committed");
    scene.camera().validate();

    const auto start = std::chrono::steady_clock::now();
    // render_pixel writes every pixel whole.
    RenderResult result{Image::for_writing(settings.width, settings.height), {}};
    const Frame frame{scene, settings,
                      CameraFilm(scene.camera(), double(settings.width) / settings.height),
                      strata_for(settings.samples_per_pixel)};

    // One tally per worker thread, reused across its tiles.
    tbb::enumerable_thread_specific<RayTally> tallies([&scene] {
        RayTally tally;
        tally.hits_per_object.assign(scene.objects().size(), 0);
        return tally;
    });
    for_each_pixel(settings, tallies, [&](int x, int y, QueryScratch& scratch, RayTally& tally) {
        render_pixel(frame, x, y, result.image.at(x, y), scratch, tally);
    });

    const auto pixels = static_cast<std::uint64_t>(result.image.pixel_count());
    const auto samples = static_cast<std::uint64_t>(settings.samples_per_pixel);
    result.stats.primary_rays = pixels * samples + (samples > 1 ? pixels : 0);
    // Integer sums: the same whichever thread counted what.
    result.stats.hits_per_object.assign(scene.objects().size(), 0);
    for (const RayTally& tally : tallies) {
        result.stats.shadow_rays += tally.shadow_rays;
        result.stats.shadow_rays_blocked += tally.shadow_rays_blocked;
        result.stats.secondary_rays += tally.secondary_rays;
        result.stats.primary_hits += tally.primary_hits;
        result.stats.centre_ray_work.nodes_visited += tally.centre_ray_work.nodes_visited;
        result.stats.centre_ray_work.primitives_tested += tally.centre_ray_work.primitives_tested;
        result.stats.centre_ray_work.boxes_tested += tally.centre_ray_work.boxes_tested;
        result.stats.centre_ray_cost += tally.centre_ray_cost;
        tally.hits_by_leaf_kind.for_each([&](std::string_view kind, std::uint64_t count) {
            result.stats.hits_by_leaf_kind[std::string(kind)] += count;
        });
        tally.solves_by_kind.for_each([&](std::string_view kind, std::uint64_t count) {
            result.stats.solves_by_kind[std::string(kind)] += count;
        });
        for (std::size_t i = 0; i < tally.hits_per_object.size(); ++i) {
            result.stats.hits_per_object[i] += tally.hits_per_object[i];
        }
    }
    result.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

CostLayer render_cost(const Scene& scene, const RenderSettings& settings) {
    validate(settings);
    require(scene.is_committed(), "render_cost", "scene", "committed", "not committed");
    scene.camera().validate();
    const Frame frame{scene, settings,
                      CameraFilm(scene.camera(), double(settings.width) / settings.height),
                      StrataGrid{}};
    CostLayer layer;
    layer.width = settings.width;
    layer.height = settings.height;
    const std::size_t pixels = std::size_t(settings.width) * std::size_t(settings.height);
    for (std::vector<float>* channel :
         {&layer.nodes, &layer.primitives, &layer.solves, &layer.total}) {
        channel->assign(pixels, 0.0f);
    }
    struct NoWorker {};
    tbb::enumerable_thread_specific<NoWorker> workers;
    for_each_pixel(settings, workers, [&](int x, int y, QueryScratch& scratch, NoWorker&) {
        TraversalCounters counters;
        QueryCost cost;
        trace_centre_ray(frame, centre_ray(frame, x, y), scratch, counters, cost);
        const std::size_t i = std::size_t(y) * std::size_t(settings.width) + std::size_t(x);
        layer.nodes[i] = static_cast<float>(cost.nodes);
        layer.primitives[i] = static_cast<float>(cost.primitives);
        layer.solves[i] = static_cast<float>(cost.solves);
        layer.total[i] = static_cast<float>(cost.total());
    });
    return layer;
}

}  // namespace csgrt
