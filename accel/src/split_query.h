#pragma once

// The one dispatch from AcceleratorBase's query<Kind, Counted>() to the three traversals a
// structure keeps when nearest, any and all hits walk differently (the regular and the
// hierarchical grid, ray classification). Private to accel/src.

#include <cstddef>

#include "csgrt/accel/accelerator.h"

namespace csgrt::detail {

/// A friend of each such structure, so its three walks stay private.
struct SplitQuery {
    /// Answers `kKind` on `structure` through its intersect_impl<kCounted> (nearest),
    /// occluded_impl<kCounted> (any) or all_hits_impl<kCounted> (all).
    /// Returns whether the query found something, as AcceleratorBase expects.
    template <QueryKind kKind, bool kCounted, class Structure>
    static bool query(const Structure& structure, const Ray& ray, QueryAnswer<kKind>& answer,
                      QueryScratch& scratch, TraversalCounters& counters) {
        if constexpr (kKind == QueryKind::kNearest) {
            return structure.template intersect_impl<kCounted>(ray, answer, scratch, counters);
        } else if constexpr (kKind == QueryKind::kAny) {
            return structure.template occluded_impl<kCounted>(ray, scratch, counters);
        } else {
            const std::size_t before = answer.size();
            structure.template all_hits_impl<kCounted>(ray, answer, scratch, counters);
            return answer.size() > before;
        }
    }
};

}  // namespace csgrt::detail
