// trace/<mesh>/bvh-batch/<rays>/threads:<n>: the batch queries of csg/batch.h over the BVH, on
// the same rays as the single-ray loops (bvh, embree) they are reported beside; and
// trace/<mesh>/bvh-loop/<rays>/threads:1, the loop a user would write instead, on the batch's
// own input.

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "benchmarks.h"
#include "csgrt/accel/factory.h"
#include "csgrt/csg/batch.h"
#include "report.h"

namespace csgrt::bench {

namespace {

/// The BVH over one mesh's float triangles, rebuilt when the workload has reloaded the mesh
/// (large meshes are released between their benchmarks).
struct BatchStructure {
    const TriangleSet<float>* set = nullptr;
    std::unique_ptr<Accelerator<TriangleSet<float>>> bvh;
};

const Accelerator<TriangleSet<float>>& batch_bvh(const std::string& mesh,
                                                 const TriangleSet<float>& set) {
    static std::map<std::string, BatchStructure> built;
    BatchStructure& entry = built[mesh];
    if (entry.set != &set || !entry.bvh) {
        entry.bvh.reset();
        entry.bvh = make_accelerator("bvh", set);
        entry.set = &set;
    }
    return *entry.bvh;
}

/// The rays as a caller of the batch holds them: an (N, 6) array of doubles (so each ray is
/// the very ray the single-ray loop traces) and the intervals.
struct RayColumns {
    std::vector<double> rays;
    std::vector<double> t_min, t_max;

    explicit RayColumns(std::span<const Ray> source) {
        rays.reserve(6 * source.size());
        for (const Ray& ray : source) {
            for (int k = 0; k < 3; ++k) rays.push_back(ray.origin[k]);
            for (int k = 0; k < 3; ++k) rays.push_back(ray.direction[k]);
            t_min.push_back(ray.t_min);
            t_max.push_back(ray.t_max);
        }
    }
    RayArrays<double> view() const {
        RayArrays<double> arrays;
        arrays.origins = strided_vectors(rays.data(), t_min.size(), 6);
        arrays.directions = strided_vectors(rays.data() + 3, t_min.size(), 6);
        arrays.t_min = t_min;
        arrays.t_max = t_max;
        return arrays;
    }
};

/// The counters of a row: rays per second, the rays, the fraction hit (from the occlusion
/// flags or the triangles written) and the mesh's size.
void report_rays(benchmark::State& state, bool occlusion, const std::vector<std::uint8_t>& occluded,
                 const std::vector<std::uint32_t>& primitive, double triangles) {
    const std::size_t n = occlusion ? occluded.size() : primitive.size();
    std::size_t hits = 0;
    for (std::size_t i = 0; i < n; ++i) {
        hits += occlusion ? occluded[i] : (primitive[i] != kNoIndex ? 1 : 0);
    }
    const auto count = static_cast<double>(n);
    state.counters["rays"] =
        benchmark::Counter(count, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["traced"] = count;
    state.counters["hit_fraction"] = count > 0.0 ? static_cast<double>(hits) / count : 0.0;
    state.counters["triangles"] = triangles;
}

}  // namespace

void register_batch_trace(Workloads& workloads, const std::string& mesh, const std::string& rays,
                          int threads) {
    const std::string name =
        "trace/" + mesh + "/bvh-batch/" + rays + "/threads:" + std::to_string(threads);
    register_info(name, {"trace", mesh, "bvh-batch", rays, threads});
    auto* benchmark = benchmark::RegisterBenchmark(
        name.c_str(), [&workloads, mesh, rays, threads](benchmark::State& state) {
            MeshWorkload& workload = workloads.get(mesh);
            const auto triangles = static_cast<double>(workload.triangles());
            const TriangleSet<float>& set = workload.float_set();
            TriangleStructure<float> structure;
            structure.triangles = &set;
            structure.structure = &batch_bvh(mesh, set);
            const RayColumns columns(workload.rays(rays).rays);
            const RayArrays<double> view = columns.view();
            const std::size_t n = view.size();
            // What the single-ray loop keeps of each answer: t and the triangle (occlusion: the
            // flag), written to caller-owned arrays.
            std::vector<double> t(n);
            std::vector<std::uint32_t> primitive(n);
            std::vector<std::uint8_t> occluded_out(n);
            NearestHitOutputs<double> outputs;
            outputs.t = t;
            outputs.primitive_id = primitive;
            BatchConfig config;
            config.threads = threads;
            const bool occlusion = rays == "shadow";
            for (auto _ : state) {
                if (occlusion) {
                    occluded(structure, view, std::span<std::uint8_t>(occluded_out), config);
                    benchmark::DoNotOptimize(occluded_out.data());
                } else {
                    intersect(structure, view, outputs, config);
                    benchmark::DoNotOptimize(t.data());
                }
                benchmark::ClobberMemory();
            }
            report_rays(state, occlusion, occluded_out, primitive, triangles);
        });
    // As the single-ray rows: one thread is the thread's CPU time (the batch runs inline on
    // it), several threads wall time.
    if (threads > 1) benchmark->UseRealTime();
    benchmark->Unit(benchmark::kMillisecond);
}

void register_user_loop_trace(Workloads& workloads, const std::string& mesh,
                              const std::string& rays) {
    const std::string name = "trace/" + mesh + "/bvh-loop/" + rays + "/threads:1";
    register_info(name, {"trace", mesh, "bvh-loop", rays, 1});
    auto* benchmark = benchmark::RegisterBenchmark(
        name.c_str(), [&workloads, mesh, rays](benchmark::State& state) {
            MeshWorkload& workload = workloads.get(mesh);
            const auto triangles = static_cast<double>(workload.triangles());
            const TriangleSet<float>& set = workload.float_set();
            const Accelerator<TriangleSet<float>>& bvh = batch_bvh(mesh, set);
            const RayColumns columns(workload.rays(rays).rays);
            const std::size_t n = columns.t_min.size();
            std::vector<double> t(n);
            std::vector<std::uint32_t> primitive(n);
            std::vector<std::uint8_t> occluded_out(n);
            QueryScratch scratch;
            const bool occlusion = rays == "shadow";
            for (auto _ : state) {
                const double* row = columns.rays.data();
                for (std::size_t i = 0; i < n; ++i, row += 6) {
                    Ray ray;
                    ray.origin = Point3(row[0], row[1], row[2]);
                    ray.direction = Vector3(row[3], row[4], row[5]);
                    ray.t_min = columns.t_min[i];
                    ray.t_max = columns.t_max[i];
                    if (occlusion) {
                        occluded_out[i] = bvh.occluded(ray, scratch) ? 1 : 0;
                    } else {
                        HitRecord record;
                        const bool hit = bvh.intersect(ray, record, scratch);
                        t[i] = hit ? record.t : kInfinity;
                        primitive[i] = hit ? record.primitive : kNoIndex;
                    }
                }
                benchmark::DoNotOptimize(occlusion ? static_cast<void*>(occluded_out.data())
                                                   : static_cast<void*>(t.data()));
                benchmark::ClobberMemory();
            }
            report_rays(state, occlusion, occluded_out, primitive, triangles);
        });
    benchmark->Unit(benchmark::kMillisecond);
}

}  // namespace csgrt::bench
