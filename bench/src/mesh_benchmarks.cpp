#include <benchmark/benchmark.h>

#include <algorithm>

#include "benchmarks.h"
#include "csgrt/accel/factory.h"
#include "peers.h"
#include "report.h"

namespace csgrt::bench {

namespace {

// Rays the counted query runs on, spread over the set: enough for a stable average.
constexpr std::size_t kCountedRays = 4096;

Variant structure_variant(std::string_view structure, bool double_precision) {
    Variant variant;
    variant.kind = Variant::Kind::kStructure;
    variant.structure = std::string(structure);
    variant.double_precision = double_precision;
    variant.name = variant.structure + (double_precision ? "-double" : "");
    return variant;
}

void set_facts(benchmark::State& state, const VariantFacts& facts, double triangles) {
    state.counters["triangles"] = triangles;
    state.counters["build_ms"] = facts.build_milliseconds;
    if (facts.bytes > 0.0) state.counters["bytes_per_tri"] = facts.bytes / triangles;
    if (facts.bytes_with_triangles > 0.0) {
        state.counters["total_bytes_per_tri"] = facts.bytes_with_triangles / triangles;
    }
    if (facts.nodes > 0.0) state.counters["nodes"] = facts.nodes;
}

}  // namespace

void Workloads::add(const std::string& name, const std::filesystem::path& path) {
    if (!has(name)) meshes_.emplace(name, std::make_unique<MeshWorkload>(name, path, sizes_));
}

MeshWorkload& Workloads::get(const std::string& name) {
    constexpr std::size_t kLarge = 500000;
    for (auto& [other, workload] : meshes_) {
        if (other != name && workload->loaded() && workload->triangles() > kLarge) {
            workload->release();
        }
    }
    return *meshes_.at(name);
}

std::vector<Variant> mesh_variants(bool with_double, bool with_robust) {
    std::vector<Variant> variants;
    Variant brute = structure_variant("brute", false);
    variants.push_back(brute);
    brute.name = "brute-boxes";
    brute.box_culling = true;
    variants.push_back(brute);
    for (std::string_view name : accelerator_names()) {
        if (name != "brute") variants.push_back(structure_variant(name, false));
    }
    Variant bvh_packets = structure_variant("bvh", false);
    bvh_packets.name = "bvh-packet";
    bvh_packets.packets = true;
    variants.push_back(bvh_packets);
    if (with_double) {
        for (std::string_view name : accelerator_names()) {
            if (name != "brute") variants.push_back(structure_variant(name, true));
        }
    }
    Variant cgal;
    cgal.kind = Variant::Kind::kCgal;
    cgal.name = "cgal";
    variants.push_back(cgal);
    if (embree_available()) {
        Variant embree;
        embree.kind = Variant::Kind::kEmbree;
        embree.name = "embree";
        variants.push_back(embree);
        Variant packets = embree;
        packets.name = "embree-packet";
        packets.packets = true;
        variants.push_back(packets);
        if (with_robust) {
            embree.name = "embree-robust";
            embree.robust = true;
            variants.push_back(embree);
        }
    }
    return variants;
}

void register_trace(Workloads& workloads, const Settings& settings, const std::string& mesh,
                    const Variant& variant, const std::string& rays, int threads) {
    const std::string name =
        "trace/" + mesh + "/" + variant.name + "/" + rays + "/threads:" + std::to_string(threads);
    register_info(name, {"trace", mesh, variant.name, rays, threads});
    auto* benchmark = benchmark::RegisterBenchmark(
        name.c_str(),
        [&workloads, settings, mesh, variant, rays, threads](benchmark::State& state) {
            MeshWorkload& workload = workloads.get(mesh);
            const auto triangles = static_cast<double>(workload.triangles());
            const RaySet& set = workload.rays(rays);
            std::span<const Ray> traced = set.rays;
            std::vector<Ray> subset;
            if (variant.is_brute()) {
                const auto count = static_cast<std::size_t>(
                    std::max(16.0, settings.brute_budget / std::max(1.0, triangles)));
                subset = spread_subset(set.rays, count);
                traced = subset;
            }
            VariantFacts facts;
            const Tracer& tracer = workload.tracer(variant, &facts);
            const bool occlusion = rays == "shadow";
            std::size_t hits = 0;
            for (auto _ : state) {
                hits = trace_all(tracer, traced, occlusion, threads);
                benchmark::DoNotOptimize(hits);
            }
            const auto count = static_cast<double>(traced.size());
            state.counters["rays"] =
                benchmark::Counter(count, benchmark::Counter::kIsIterationInvariantRate);
            state.counters["traced"] = count;
            state.counters["hit_fraction"] = count > 0.0 ? static_cast<double>(hits) / count : 0.0;
            set_facts(state, facts, triangles);
            TraversalCounters counters;
            const std::vector<Ray> sample =
                spread_subset(traced, std::min<std::size_t>(kCountedRays, traced.size()));
            if (!sample.empty() && tracer.count(sample, occlusion, counters)) {
                const auto per_ray = 1.0 / static_cast<double>(sample.size());
                state.counters["nodes_per_ray"] = counters.nodes_visited * per_ray;
                state.counters["prims_per_ray"] = counters.primitives_tested * per_ray;
                state.counters["boxes_per_ray"] = counters.boxes_tested * per_ray;
            }
        });
    // One thread: the thread's CPU time, which other processes on a shared machine barely
    // disturb. Several threads: wall time, the only time that shows the scaling.
    if (threads > 1) benchmark->UseRealTime();
    benchmark->Unit(benchmark::kMillisecond);
}

void register_build(Workloads& workloads, const std::string& mesh, const Variant& variant,
                    int threads) {
    const std::string name =
        "build/" + mesh + "/" + variant.name + "/threads:" + std::to_string(threads);
    register_info(name, {"build", mesh, variant.name, "", threads});
    auto* benchmark = benchmark::RegisterBenchmark(
        name.c_str(), [&workloads, mesh, variant, threads](benchmark::State& state) {
            MeshWorkload& workload = workloads.get(mesh);
            const auto triangles = static_cast<double>(workload.triangles());
            workload.float_set();
            if (variant.double_precision) workload.double_set();
            VariantFacts facts;
            for (auto _ : state) facts = workload.build_once(variant, threads);
            set_facts(state, facts, triangles);
            state.counters["triangles_per_s"] =
                benchmark::Counter(triangles, benchmark::Counter::kIsIterationInvariantRate);
        });
    // A one-thread build may still run on a TBB or Embree worker, so the process's CPU time
    // is its work; several threads: wall time.
    if (threads > 1) {
        benchmark->UseRealTime();
    } else {
        benchmark->MeasureProcessCPUTime();
    }
    benchmark->Unit(benchmark::kMillisecond);
}

}  // namespace csgrt::bench
