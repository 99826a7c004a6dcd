#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "workload.h"

namespace csgrt::bench {

/// What a run measures and how much of it: set by --quick, the default, or --full.
struct Settings {
    std::string mode = "standard";
    RaySetSizes sizes;
    /// Triangle tests brute force may do per pass over a ray set: it traces an evenly spread
    /// subset of max(16, budget / triangles) rays, so it costs the same on every mesh.
    double brute_budget = 1e8;
    /// "All threads": the machine's hardware threads.
    int threads = 1;
    /// The repository's data/ folder (meshes, generated meshes, scenes).
    std::filesystem::path data;
    /// Image width and height of the accuracy section's camera rays.
    int accuracy_width = 256;
    /// Rays each accuracy variant is timed and judged on.
    std::size_t accuracy_rays = 4096;
    /// Width and height of a CSG scene's frame.
    int csg_width = 512;
};

/// The meshes of the run by name, loaded on first use. Before a mesh is handed out, other
/// loaded meshes above half a million triangles are released, so the largest ones are never
/// in memory together (benchmarks run in registration order, mesh by mesh).
class Workloads {
public:
    explicit Workloads(RaySetSizes sizes) : sizes_(sizes) {}

    void add(const std::string& name, const std::filesystem::path& path);
    bool has(const std::string& name) const { return meshes_.count(name) != 0; }
    MeshWorkload& get(const std::string& name);

private:
    RaySetSizes sizes_;
    std::map<std::string, std::unique_ptr<MeshWorkload>> meshes_;
};

/// The variants traced on a mesh: brute force (plain and with box culling), every registered
/// structure over float triangles (and over double when `with_double`), CGAL, and Embree
/// (plain and, when `with_robust`, robust) when available.
std::vector<Variant> mesh_variants(bool with_double, bool with_robust);

/// trace/<mesh>/<variant>/<rays>/threads:<n>: Mrays/s of the nearest-hit query (occlusion for
/// "shadow"), with build time, memory and per-ray counts as counters.
void register_trace(Workloads& workloads, const Settings& settings, const std::string& mesh,
                    const Variant& variant, const std::string& rays, int threads);
/// trace/<mesh>/bvh-batch/<rays>/threads:<n>: the batch queries (csg/batch.h) over the BVH on
/// the same rays, beside the single-ray loops (bench/src/batch_benchmarks.cpp).
void register_batch_trace(Workloads& workloads, const std::string& mesh, const std::string& rays,
                          int threads);
/// trace/<mesh>/bvh-loop/<rays>/threads:1: the loop a user writes without the batch, over the
/// batch's own input: a Ray built from each row of the same (N, 6) array, the BVH's
/// Accelerator::intersect (occluded for "shadow"), t and the triangle written to arrays.
void register_user_loop_trace(Workloads& workloads, const std::string& mesh,
                              const std::string& rays);
/// build/<mesh>/<variant>/threads:<n>: the build alone, repeated.
void register_build(Workloads& workloads, const std::string& mesh, const Variant& variant,
                    int threads);

/// accuracy/<group>/<variant>: run time against error (bench/src/accuracy.cpp).
void register_accuracy_benchmarks(Workloads& workloads, const Settings& settings);

/// The scene files of `data`/scenes, sorted.
std::vector<std::filesystem::path> csg_scene_files(const std::filesystem::path& data);

/// csg/<scene>/<structure>/threads:<n>: a frame of each scene file with shadows, its objects
/// under each registered structure ("brute": no hierarchical bounding boxes), with the object
/// and box tests per camera ray (bench/src/csg_scenes.cpp).
void register_csg_benchmarks(const Settings& settings);

}  // namespace csgrt::bench
