#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "csgrt/core/hit.h"
#include "csgrt/core/query_scratch.h"
#include "csgrt/core/ray.h"

namespace csgrt {

/// The three primitive sets every structure is built for (accel/shape_set.h,
/// accel/triangle_set.h): each structure's header declares its instantiations over them
/// `extern template`, and its source defines them.
class ShapeSet;
template <class Real>
class TriangleSet;

/// Per-ray work, accumulated over the rays of a counted query.
struct TraversalCounters {
    /// Tree nodes, grid cells or ray-space cells visited.
    std::uint64_t nodes_visited = 0;
    /// Primitive intersection tests performed.
    std::uint64_t primitives_tested = 0;
    /// Box tests (node or primitive boxes), where the structure makes them.
    std::uint64_t boxes_tested = 0;
};

/// What a structure reports about itself after `build`.
struct AcceleratorStats {
    std::string name;
    double build_milliseconds = 0.0;
    /// Memory the structure owns (not counting the primitive set).
    std::size_t bytes = 0;
    /// Tree nodes, or grid cells, or ray-space cells.
    std::size_t nodes = 0;
    /// Primitive references held (a primitive in several cells counts several times).
    std::size_t references = 0;
    std::size_t primitives = 0;
    /// A one-line description of structure-specific figures (resolution, depth, SAH cost...).
    std::string details;
};

/// An acceleration structure over a primitive set (accel/primitive_set.h), chosen at run time
/// through `make_accelerator`. One virtual call per query; the traversal inside is a template
/// over the set, so primitive tests are direct calls. The set must outlive the structure.
/// Queries are const and thread-safe once `build` has returned.
template <class Set>
class Accelerator {
public:
    virtual ~Accelerator() = default;

    /// The factory name: "brute", "grid", "hgrid", "rayclass" or "bvh".
    virtual std::string_view name() const = 0;

    /// Nearest hit in [ray.t_min, ray.t_max] (an invalid ray, see is_valid, never hits). On success
    /// writes the set's fields of `record` (t, primitive or object, u, v) and returns true.
    virtual bool intersect(const Ray& ray, HitRecord& record, QueryScratch& scratch) const = 0;
    /// Whether any primitive is hit in [ray.t_min, ray.t_max]; stops at the first.
    virtual bool occluded(const Ray& ray, QueryScratch& scratch) const = 0;

    /// The same queries, also counting the work done into `counters` (a separate entry point
    /// so the uncounted traversal pays nothing for counting).
    virtual bool intersect_counted(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                                   TraversalCounters& counters) const = 0;
    virtual bool occluded_counted(const Ray& ray, QueryScratch& scratch,
                                  TraversalCounters& counters) const = 0;

    /// Appends every hit in [ray.t_min, ray.t_max], each primitive at most once, in no
    /// particular order (meshes sort them into spans for CSG).
    virtual void all_hits(const Ray& ray, std::vector<HitRecord>& hits,
                          QueryScratch& scratch) const = 0;

    virtual AcceleratorStats stats() const = 0;
};

/// What one structure query answers: the nearest hit (intersect), whether anything is hit
/// (occluded), or every hit (all_hits).
enum class QueryKind { kNearest, kAny, kAll };

/// Where a query of kind kKind writes its answer: the nearest hit's record, nothing, or the
/// list the hits are appended to.
struct NoAnswer {};
template <QueryKind kKind>
using QueryAnswer = std::conditional_t<
    kKind == QueryKind::kNearest, HitRecord,
    std::conditional_t<kKind == QueryKind::kAll, std::vector<HitRecord>, NoAnswer>>;

/// The Accelerator overrides written once (CRTP). A structure derives from
/// AcceleratorBase<Structure, Set>, names itself in `static constexpr std::string_view kName`,
/// fills `stats_` in its build, and answers every query in one member template
///
///     template <QueryKind kKind, bool kCounted>
///     bool query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
///                TraversalCounters& counters) const;
///
/// returning whether anything was found (for kNearest writing `answer` only then). The counted
/// and uncounted queries are separate instances, so the uncounted traversal pays nothing for
/// counting. The overrides are defined in accel/src/accelerator_base.h, which the structure's
/// source includes and instantiates with `template class AcceleratorBase<Structure<S>, S>;`
/// next to its query, so no other file needs to see the query.
template <class Derived, class Set>
class AcceleratorBase : public Accelerator<Set> {
public:
    std::string_view name() const final;
    bool intersect(const Ray& ray, HitRecord& record, QueryScratch& scratch) const final;
    bool occluded(const Ray& ray, QueryScratch& scratch) const final;
    bool intersect_counted(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                           TraversalCounters& counters) const final;
    bool occluded_counted(const Ray& ray, QueryScratch& scratch,
                          TraversalCounters& counters) const final;
    void all_hits(const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch) const final;
    /// The figures the structure's build wrote into stats_ (a structure whose figures grow
    /// after the build overrides this).
    AcceleratorStats stats() const override;

protected:
    AcceleratorStats stats_;

private:
    const Derived& derived() const { return static_cast<const Derived&>(*this); }
};

}  // namespace csgrt
