#include "workload.h"

#include <malloc.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <Eigen/Geometry>
#include <chrono>
#include <stdexcept>

#include "csgrt/accel/bvh.h"
#include "csgrt/accel/factory.h"
#include "peers.h"

namespace csgrt::bench {

namespace {

// Seeds of the generated ray sets: fixed, so every run and every variant traces the same rays.
constexpr std::uint64_t kIncoherentSeed = 0x1e5c0de;

// Bytes the main heap arena has in use: CGAL allocates its tree on the calling thread, so the
// difference across its construction is what it holds (glibc's mallinfo2).
std::size_t heap_in_use() {
    const struct mallinfo2 info = mallinfo2();
    return info.uordblks + info.hblkhd;
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

template <class Set>
VariantFacts facts_of(const Accelerator<Set>& structure, const Set& set) {
    const AcceleratorStats stats = structure.stats();
    VariantFacts facts;
    facts.build_milliseconds = stats.build_milliseconds;
    facts.bytes = static_cast<double>(stats.bytes);
    facts.bytes_with_triangles = static_cast<double>(stats.bytes + set.bytes());
    facts.nodes = static_cast<double>(stats.nodes);
    facts.references = static_cast<double>(stats.references);
    facts.details = stats.details;
    return facts;
}

AcceleratorConfig config_of(const Variant& variant) {
    AcceleratorConfig config;
    config.brute_force.box_culling = variant.box_culling;
    return config;
}

}  // namespace

std::string fastest_structure() {
    const auto names = accelerator_names();
    for (std::string_view name : names) {
        if (name == "bvh") return std::string(name);
    }
    for (std::string_view name : names) {
        if (name != "brute") return std::string(name);
    }
    return {};
}

struct MeshWorkload::Built {
    std::unique_ptr<Accelerator<TriangleSet<float>>> float_structure;
    std::unique_ptr<Accelerator<TriangleSet<double>>> double_structure;
    std::unique_ptr<Tracer> tracer;
    VariantFacts facts;
};

MeshWorkload::MeshWorkload(std::string name, std::filesystem::path path, RaySetSizes sizes)
    : name_(std::move(name)), path_(std::move(path)), sizes_(sizes) {}

MeshWorkload::~MeshWorkload() = default;

void MeshWorkload::load() {
    if (data_) return;
    data_ = load_mesh(path_);
    box_ = Aabb();
    for (const auto& triangle : data_->triangles) {
        for (std::uint32_t index : triangle) box_.extend(data_->vertices[index]);
    }
}

std::size_t MeshWorkload::triangles() {
    load();
    return data_->triangles.size();
}

const TriangleMeshData& MeshWorkload::data() {
    load();
    return *data_;
}

const Aabb& MeshWorkload::box() {
    load();
    return box_;
}

Camera MeshWorkload::camera() {
    return framing_camera(box());
}

const TriangleSet<float>& MeshWorkload::float_set() {
    if (!float_set_) {
        load();
        float_set_ = std::make_unique<TriangleSet<float>>(data_->vertices, data_->triangles);
    }
    return *float_set_;
}

const TriangleSet<double>& MeshWorkload::double_set() {
    if (!double_set_) {
        load();
        double_set_ = std::make_unique<TriangleSet<double>>(data_->vertices, data_->triangles);
    }
    return *double_set_;
}

const CgalReference& MeshWorkload::cgal() {
    if (!cgal_) {
        const TriangleSet<float>& set = float_set();
        const std::size_t before = heap_in_use();
        const auto start = std::chrono::steady_clock::now();
        cgal_ = std::make_unique<CgalReference>(set);
        cgal_facts_.build_milliseconds = milliseconds_since(start);
        cgal_facts_.bytes_with_triangles = static_cast<double>(heap_in_use() - before);
    }
    return *cgal_;
}

const RaySet& MeshWorkload::rays(const std::string& kind) {
    auto found = rays_.find(kind);
    if (found != rays_.end()) return found->second;
    RaySet set;
    if (kind == "camera") {
        set = camera_rays(camera(), sizes_.camera_width, sizes_.camera_width);
    } else if (kind == "incoherent") {
        set = incoherent_rays(box(), sizes_.incoherent, kIncoherentSeed);
    } else if (kind == "shadow") {
        const RaySet& primary = rays("camera");
        const std::vector<SurfaceHit> hits = surface_hits(primary.rays);
        // Off the surface by far more than the float triangles' rounding (a few 1e-7 of the
        // coordinates) and far less than any feature of the mesh.
        set = shadow_rays(primary.rays, hits, default_light(box()), 1e-5 * box().diagonal().norm());
    } else {
        throw std::invalid_argument("unknown ray set '" + kind + "'");
    }
    return rays_.emplace(kind, std::move(set)).first->second;
}

std::vector<SurfaceHit> MeshWorkload::surface_hits(std::span<const Ray> rays) {
    const TriangleSet<float>& set = float_set();
    std::vector<SurfaceHit> hits(rays.size());
    auto normal_of = [&](std::uint32_t primitive) {
        const Vector3 a = set.corner(primitive, 0).cast<double>();
        const Vector3 b = set.corner(primitive, 1).cast<double>();
        const Vector3 c = set.corner(primitive, 2).cast<double>();
        return Vector3((b - a).cross(c - a).normalized());
    };
    const std::string fastest = fastest_structure();
    if (!fastest.empty()) {
        Variant variant;
        variant.name = fastest;
        variant.structure = fastest;
        tracer(variant);
        const auto& structure = *built_.at(fastest)->float_structure;
        const auto threads = static_cast<int>(std::thread::hardware_concurrency());
        for_ray_blocks(
            rays.size(), threads, [&](std::size_t begin, std::size_t end, QueryScratch& scratch) {
                for (std::size_t i = begin; i < end; ++i) {
                    HitRecord record;
                    if (structure.intersect(rays[i], record, scratch)) {
                        hits[i] = SurfaceHit{true, record.t, normal_of(record.primitive)};
                    }
                }
                return std::size_t{0};
            });
        return hits;
    }
    const CgalReference& reference = cgal();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (const auto primitive = reference.first_intersected_primitive(rays[i])) {
            const auto t = static_cast<double>(reference.plane_t(rays[i], *primitive));
            hits[i] = SurfaceHit{true, t, normal_of(*primitive)};
        }
    }
    return hits;
}

const Tracer& MeshWorkload::tracer(const Variant& variant, VariantFacts* facts) {
    auto found = built_.find(variant.name);
    if (found == built_.end()) {
        auto built = std::make_unique<Built>();
        switch (variant.kind) {
            case Variant::Kind::kStructure:
                if (variant.double_precision) {
                    built->double_structure =
                        make_accelerator(variant.structure, double_set(), config_of(variant));
                    built->tracer = std::make_unique<AcceleratorTracer<TriangleSet<double>>>(
                        *built->double_structure);
                    built->facts = facts_of(*built->double_structure, double_set());
                } else {
                    built->float_structure =
                        make_accelerator(variant.structure, float_set(), config_of(variant));
                    const auto* bvh =
                        dynamic_cast<const Bvh<TriangleSet<float>>*>(built->float_structure.get());
                    if (variant.packets && bvh != nullptr) {
                        built->tracer = std::make_unique<BvhPacketTracer>(*bvh);
                    } else {
                        built->tracer = std::make_unique<AcceleratorTracer<TriangleSet<float>>>(
                            *built->float_structure);
                    }
                    built->facts = facts_of(*built->float_structure, float_set());
                }
                break;
            case Variant::Kind::kCgal:
                built->tracer = make_cgal_tracer(cgal());
                built->facts = cgal_facts_;
                break;
            case Variant::Kind::kEmbree: {
                EmbreeBuild build;
                built->tracer = make_embree_tracer(float_set(), variant.robust,
                                                   tbb::info::default_concurrency(), &build,
                                                   variant.packets);
                built->facts.build_milliseconds = build.build_milliseconds;
                built->facts.bytes_with_triangles = static_cast<double>(build.bytes);
                built->facts.bytes = static_cast<double>(build.bytes - build.buffer_bytes);
                break;
            }
        }
        found = built_.emplace(variant.name, std::move(built)).first;
    }
    if (facts != nullptr) *facts = found->second->facts;
    return *found->second->tracer;
}

VariantFacts MeshWorkload::build_once(const Variant& variant, int threads) {
    // TBB (the BVH's parallel build, Embree's) uses at most `threads` threads meanwhile.
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(std::max(1, threads)));
    VariantFacts facts;
    switch (variant.kind) {
        case Variant::Kind::kStructure:
            if (variant.double_precision) {
                facts =
                    facts_of(*make_accelerator(variant.structure, double_set(), config_of(variant)),
                             double_set());
            } else {
                facts =
                    facts_of(*make_accelerator(variant.structure, float_set(), config_of(variant)),
                             float_set());
            }
            break;
        case Variant::Kind::kCgal: {
            const std::size_t before = heap_in_use();
            const auto start = std::chrono::steady_clock::now();
            {
                const CgalReference reference(float_set());
                facts.build_milliseconds = milliseconds_since(start);
                facts.bytes_with_triangles = static_cast<double>(heap_in_use() - before);
            }
            break;
        }
        case Variant::Kind::kEmbree: {
            EmbreeBuild build;
            make_embree_tracer(float_set(), variant.robust, threads, &build);
            facts.build_milliseconds = build.build_milliseconds;
            facts.bytes_with_triangles = static_cast<double>(build.bytes);
            facts.bytes = static_cast<double>(build.bytes - build.buffer_bytes);
            break;
        }
    }
    return facts;
}

void MeshWorkload::release() {
    built_.clear();
    cgal_.reset();
    cgal_facts_ = VariantFacts{};
    rays_.clear();
    float_set_.reset();
    double_set_.reset();
    data_.reset();
}

}  // namespace csgrt::bench
