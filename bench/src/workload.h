#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/reference/cgal_reference.h"
#include "csgrt/mesh/mesh_io.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/bench/ray_sets.h"
#include "csgrt/csg/camera.h"
#include "tracer.h"

namespace csgrt::bench {

/// One thing a mesh benchmark traces through: a csgrt structure (by factory name, over float or
/// double triangles), CGAL's AABB tree, or Embree.
struct Variant {
    enum class Kind { kStructure, kCgal, kEmbree };

    /// The name in benchmark names and reports: "bvh", "bvh-double", "brute-boxes", "cgal",
    /// "embree-robust"...
    std::string name;
    Kind kind = Kind::kStructure;
    /// The factory name (kStructure).
    std::string structure;
    bool double_precision = false;
    bool box_culling = false;
    /// Embree's RTC_SCENE_FLAG_ROBUST.
    bool robust = false;
    /// Packet queries instead of one ray at a time: Embree's rtcIntersect8 / rtcOccluded8,
    /// or the BVH's intersect_packets / occluded_packets (structure "bvh", float).
    bool packets = false;

    /// Brute force is O(N) per ray, so it traces a bounded subset of each ray set.
    bool is_brute() const { return kind == Kind::kStructure && structure == "brute"; }
};

/// What a built variant reports about itself.
struct VariantFacts {
    double build_milliseconds = 0.0;
    /// Memory of the structure alone, and with the triangles it needs (a csgrt structure's
    /// TriangleSet, Embree's vertex and index buffers, CGAL's own copy of the triangles).
    double bytes = 0.0;
    double bytes_with_triangles = 0.0;
    double nodes = 0.0;
    double references = 0.0;
    std::string details;
};

/// How many rays each generated set has.
struct RaySetSizes {
    int camera_width = 256;
    std::size_t incoherent = 65536;
};

/// A mesh and everything traced through it, each made on first use and kept: the triangles in
/// float and double, the ray sets (fixed seeds), the variants built over them, CGAL's tree.
/// Used from the benchmark's main thread only (benchmarks run one at a time); the tracers it
/// hands out are then queried from several threads.
class MeshWorkload {
public:
    MeshWorkload(std::string name, std::filesystem::path path, RaySetSizes sizes);
    ~MeshWorkload();
    MeshWorkload(const MeshWorkload&) = delete;
    MeshWorkload& operator=(const MeshWorkload&) = delete;

    const std::string& name() const { return name_; }
    const std::filesystem::path& path() const { return path_; }
    /// Loads the mesh if needed.
    std::size_t triangles();
    const TriangleMeshData& data();
    const Aabb& box();
    Camera camera();

    const TriangleSet<float>& float_set();
    const TriangleSet<double>& double_set();
    const CgalReference& cgal();

    /// "camera", "incoherent" or "shadow" (from the camera rays' hits toward default_light).
    const RaySet& rays(const std::string& kind);

    /// The variant, built on first use with every thread available; its facts in `facts`.
    const Tracer& tracer(const Variant& variant, VariantFacts* facts = nullptr);

    /// Builds the variant afresh (not kept) on `threads` threads, for the build benchmark;
    /// returns its facts.
    VariantFacts build_once(const Variant& variant, int threads);

    /// The nearest hit (t and unit geometric normal) of each ray, found with the fastest
    /// registered structure (or CGAL when only brute force is registered).
    std::vector<SurfaceHit> surface_hits(std::span<const Ray> rays);

    /// Frees everything but the name and path (large meshes are dropped once their
    /// benchmarks have run).
    void release();
    bool loaded() const { return data_.has_value(); }

private:
    struct Built;

    void load();

    std::string name_;
    std::filesystem::path path_;
    RaySetSizes sizes_;
    std::optional<TriangleMeshData> data_;
    Aabb box_;
    std::unique_ptr<TriangleSet<float>> float_set_;
    std::unique_ptr<TriangleSet<double>> double_set_;
    std::unique_ptr<CgalReference> cgal_;
    VariantFacts cgal_facts_;
    std::map<std::string, RaySet> rays_;
    std::map<std::string, std::unique_ptr<Built>> built_;
};

/// The structure used to find primary hits for shadow rays: "bvh" if registered, else the
/// first registered name other than brute force, else empty (CGAL is used).
std::string fastest_structure();

}  // namespace csgrt::bench
