#pragma once

// The definitions of AcceleratorBase's overrides (accel/accelerator.h), for the structures'
// sources only: each instantiates them once, beside the query they call.

#include "csgrt/accel/accelerator.h"
#include "csgrt/core/query_cost.h"

namespace csgrt {

namespace detail {

/// An uncounted query made while a CostScope is open on its scratch (a structure inside a mesh
/// or a compound, reached from a counted query): the counted query, its work added to the
/// scratch's cost. Kept out of line so the uncounted query's code stays as it was.
template <QueryKind kKind, class Base>
[[gnu::noinline]] bool query_into_cost(const Base& structure, const Ray& ray,
                                       QueryAnswer<kKind>& answer, QueryScratch& scratch) {
    TraversalCounters counters;
    bool found;
    if constexpr (kKind == QueryKind::kNearest) {
        found = structure.Base::intersect_counted(ray, answer, scratch, counters);
    } else {
        found = structure.Base::occluded_counted(ray, scratch, counters);
    }
    QueryCost* cost = scratch.cost();
    cost->nodes += counters.nodes_visited;
    cost->primitives += counters.primitives_tested;
    return found;
}

/// The every-hit walk made while a CostScope is open (a mesh's spans as a CSG operand, a
/// large compound's): the counted walk of the structure's query, its work added to the
/// scratch's cost. Out of line, as above.
template <class Structure>
[[gnu::noinline]] void all_hits_into_cost(const Structure& structure, const Ray& ray,
                                          std::vector<HitRecord>& hits, QueryScratch& scratch) {
    TraversalCounters counters;
    structure.template query<QueryKind::kAll, true>(ray, hits, scratch, counters);
    QueryCost* cost = scratch.cost();
    cost->nodes += counters.nodes_visited;
    cost->primitives += counters.primitives_tested;
}

}  // namespace detail

template <class Derived, class Set>
std::string_view AcceleratorBase<Derived, Set>::name() const {
    return Derived::kName;
}

template <class Derived, class Set>
bool AcceleratorBase<Derived, Set>::intersect(const Ray& ray, HitRecord& record,
                                              QueryScratch& scratch) const {
    if (scratch.cost() != nullptr) [[unlikely]]
        return detail::query_into_cost<QueryKind::kNearest>(*this, ray, record, scratch);
    TraversalCounters unused;
    return derived().template query<QueryKind::kNearest, false>(ray, record, scratch, unused);
}

template <class Derived, class Set>
bool AcceleratorBase<Derived, Set>::occluded(const Ray& ray, QueryScratch& scratch) const {
    NoAnswer none;
    if (scratch.cost() != nullptr) [[unlikely]]
        return detail::query_into_cost<QueryKind::kAny>(*this, ray, none, scratch);
    TraversalCounters unused;
    return derived().template query<QueryKind::kAny, false>(ray, none, scratch, unused);
}

template <class Derived, class Set>
bool AcceleratorBase<Derived, Set>::intersect_counted(const Ray& ray, HitRecord& record,
                                                      QueryScratch& scratch,
                                                      TraversalCounters& counters) const {
    return derived().template query<QueryKind::kNearest, true>(ray, record, scratch, counters);
}

template <class Derived, class Set>
bool AcceleratorBase<Derived, Set>::occluded_counted(const Ray& ray, QueryScratch& scratch,
                                                     TraversalCounters& counters) const {
    NoAnswer none;
    return derived().template query<QueryKind::kAny, true>(ray, none, scratch, counters);
}

template <class Derived, class Set>
void AcceleratorBase<Derived, Set>::all_hits(const Ray& ray, std::vector<HitRecord>& hits,
                                             QueryScratch& scratch) const {
    if (scratch.cost() != nullptr) [[unlikely]] {
        detail::all_hits_into_cost(derived(), ray, hits, scratch);
        return;
    }
    TraversalCounters unused;
    derived().template query<QueryKind::kAll, false>(ray, hits, scratch, unused);
}

template <class Derived, class Set>
AcceleratorStats AcceleratorBase<Derived, Set>::stats() const {
    return stats_;
}

}  // namespace csgrt

/// Instantiates AcceleratorBase's overrides for `Structure` over each primitive set a
/// structure serves (the two triangle sets and ShapeSet), in the source that defines
/// Structure::query: the list of sets is written here once, not in every structure.
#define CSGRT_INSTANTIATE_ACCELERATOR_BASE(Structure)                                          \
    template class csgrt::AcceleratorBase<Structure<csgrt::TriangleSet<float>>,                \
                                          csgrt::TriangleSet<float>>;                          \
    template class csgrt::AcceleratorBase<Structure<csgrt::TriangleSet<double>>,               \
                                          csgrt::TriangleSet<double>>;                         \
    template class csgrt::AcceleratorBase<Structure<csgrt::ShapeSet>, csgrt::ShapeSet>
