#pragma once

// The definitions of AcceleratorBase's overrides (accel/accelerator.h), for the structures'
// sources only: each instantiates them once, beside the query they call.

#include "csgrt/accel/accelerator.h"

namespace csgrt {

template <class Derived, class Set>
std::string_view AcceleratorBase<Derived, Set>::name() const {
    return Derived::kName;
}

template <class Derived, class Set>
bool AcceleratorBase<Derived, Set>::intersect(const Ray& ray, HitRecord& record,
                                              QueryScratch& scratch) const {
    TraversalCounters unused;
    return derived().template query<QueryKind::kNearest, false>(ray, record, scratch, unused);
}

template <class Derived, class Set>
bool AcceleratorBase<Derived, Set>::occluded(const Ray& ray, QueryScratch& scratch) const {
    TraversalCounters unused;
    NoAnswer none;
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
    TraversalCounters unused;
    derived().template query<QueryKind::kAll, false>(ray, hits, scratch, unused);
}

template <class Derived, class Set>
AcceleratorStats AcceleratorBase<Derived, Set>::stats() const {
    return stats_;
}

}  // namespace csgrt
