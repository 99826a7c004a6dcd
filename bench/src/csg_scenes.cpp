// CSG scenes: the time per frame of each scene of data/scenes/ rendered with shadows, its
// top-level objects organised by each registered structure: "brute" is the scene without
// hierarchical bounding boxes (every object tested on every ray), the others build a hierarchy
// of boxes (BVH) or cells over them; and the box and object tests per camera ray.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <memory>

#include "benchmarks.h"
#include "csgrt/accel/factory.h"
#include "csgrt/bench/frame_plan.h"
#include "csgrt/bench/ray_sets.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/renderer.h"
#include "report.h"

namespace csgrt::bench {

namespace {

// Camera rays the counted query runs on, spread over the frame.
constexpr std::size_t kCountedRays = 1024;

double process_cpu_seconds() {
    timespec now{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/// The scenes, loaded and committed once per structure (benchmarks run one at a time on the
/// main thread).
class SceneCache {
public:
    const Scene& get(const std::filesystem::path& path, const std::string& structure) {
        const std::string key = path.string() + "|" + structure;
        auto found = scenes_.find(key);
        if (found == scenes_.end()) {
            auto scene = std::make_unique<Scene>(load_scene(path));
            SceneConfig config;
            config.accelerator = structure;
            scene->commit(config);
            found = scenes_.emplace(key, std::move(scene)).first;
        }
        return *found->second;
    }

private:
    std::map<std::string, std::unique_ptr<Scene>> scenes_;
};

void register_scene(const std::shared_ptr<SceneCache>& cache, const Settings& settings,
                    const std::filesystem::path& path, const std::string& structure, int threads) {
    const std::string scene_name = path.stem().string();
    const std::string name =
        "csg/" + scene_name + "/" + structure + "/threads:" + std::to_string(threads);
    register_info(name, {"csg", scene_name, structure, "frame", threads});
    auto* benchmark = benchmark::RegisterBenchmark(
        name.c_str(), [cache, settings, path, structure, threads](benchmark::State& state) {
            const Scene* loaded = nullptr;
            try {
                loaded = &cache->get(path, structure);
            } catch (const std::exception& error) {
                state.SkipWithError(error.what());
                return;
            }
            const Scene& scene = *loaded;
            const auto objects = static_cast<double>(scene.objects().size());
            const double rays_per_pixel = 1.0 + static_cast<double>(scene.lights().size());
            // Brute force tests every object on every ray: a large scene is timed on a smaller
            // frame of the same view, within the run's budget of object tests.
            const FramePlan plan =
                structure == "brute"
                    ? plan_frame(settings.csg_width, objects, rays_per_pixel, settings.brute_budget)
                    : FramePlan{settings.csg_width, 1.0};
            RenderSettings render_settings;
            render_settings.width = plan.width;
            render_settings.height = plan.width;
            render_settings.threads = threads;
            RenderStats stats;
            double wall_seconds = 0.0;
            for (auto _ : state) {
                // One thread: the process's CPU time (the render runs on a oneTBB thread,
                // capped at one); several: wall time.
                const double cpu_start = process_cpu_seconds();
                const auto wall_start = std::chrono::steady_clock::now();
                const RenderResult result = render(scene, render_settings);
                const double cpu = process_cpu_seconds() - cpu_start;
                wall_seconds =
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start)
                        .count();
                const double seconds = threads > 1 ? wall_seconds : cpu;
                stats = result.stats;
                state.SetIterationTime(seconds * plan.scale);
            }
            const auto rays = static_cast<double>(stats.primary_rays + stats.shadow_rays);
            state.counters["rays"] = benchmark::Counter(
                rays * plan.scale, benchmark::Counter::kIsIterationInvariantRate);
            state.counters["shadow_rays_per_pixel"] =
                static_cast<double>(stats.shadow_rays) /
                (static_cast<double>(plan.width) * static_cast<double>(plan.width));
            state.counters["objects"] = objects;
            // The last frame's wall time, for the thread scaling (wall against wall).
            state.counters["wall_ms"] = wall_seconds * plan.scale * 1e3;
            state.counters["frame_width"] = settings.csg_width;
            state.counters["rendered_width"] = plan.width;
            // The top-level structure's work per camera ray (Scene::intersect_counted): the
            // object tests (bounded ones through the structure, unbounded ones always) and the
            // boxes and nodes visited. Brute force is counted on fewer rays within the budget.
            const double affordable = settings.brute_budget / (10.0 * std::max(1.0, objects));
            const auto count = structure == "brute"
                                   ? std::clamp<std::size_t>(static_cast<std::size_t>(affordable),
                                                             16, kCountedRays)
                                   : kCountedRays;
            const RaySet camera =
                camera_rays(scene.camera(), settings.csg_width, settings.csg_width);
            const std::vector<Ray> sample = spread_subset(camera.rays, count);
            TraversalCounters counters;
            QueryScratch scratch;
            for (const Ray& ray : sample) scene.intersect_counted(ray, scratch, counters);
            const double per_ray = 1.0 / static_cast<double>(sample.size());
            state.counters["objects_per_ray"] = counters.primitives_tested * per_ray;
            state.counters["boxes_per_ray"] = counters.boxes_tested * per_ray;
            state.counters["nodes_per_ray"] = counters.nodes_visited * per_ray;
            const AcceleratorStats structure_stats = scene.accelerator_stats();
            state.counters["build_ms"] = structure_stats.build_milliseconds;
        });
    benchmark->UseManualTime();
    benchmark->Unit(benchmark::kMillisecond);
}

}  // namespace

std::vector<std::filesystem::path> csg_scene_files(const std::filesystem::path& data) {
    std::vector<std::filesystem::path> files;
    const std::filesystem::path folder = data / "scenes";
    if (!std::filesystem::is_directory(folder)) return files;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        if (entry.is_regular_file() && entry.path().extension() == ".json") {
            files.push_back(entry.path());
        }
    }
    std::sort(files.begin(), files.end());
    return files;
}

void register_csg_benchmarks(const Settings& settings) {
    auto cache = std::make_shared<SceneCache>();
    for (const std::filesystem::path& path : csg_scene_files(settings.data)) {
        for (std::string_view structure : accelerator_names()) {
            register_scene(cache, settings, path, std::string(structure), 1);
        }
        if (settings.mode == "quick" || settings.threads <= 1) continue;
        for (std::string_view structure : accelerator_names()) {
            if (structure == "brute") continue;
            register_scene(cache, settings, path, std::string(structure), settings.threads);
        }
    }
}

}  // namespace csgrt::bench
