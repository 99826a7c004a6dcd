#pragma once

// The batch queries' groups of rays (csg/src/batch.cpp only).

#include <algorithm>
#include <cstddef>

#include "csgrt/accel/bvh.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/csg/batch.h"

namespace csgrt::detail {

/// Up to kRays consecutive rays of a batch, converted once and traced together: through the
/// BVH's packet queries when they share one origin (camera rays: the packet walks them as
/// one, and answers as the single-ray queries do, bit for bit), else one at a time. Only rays
/// with one origin go through the packet query: for others (shadow rays from a surface,
/// incoherent rays) it goes ray by ray anyway, after setting up every lane, and the batch's
/// shadow rays on the armadillo cost 1,545 instructions a ray that way against 1,360 through
/// the single-ray query (callgrind). Ray by ray, a BVH is called directly (Bvh is final, so
/// the call is not virtual); any other structure through its Accelerator interface.
///
/// The batch's writes go over a whole group output by output, after the traversals: the
/// choice of outputs is made once a group instead of once a ray, and a miss is a select
/// rather than a branch that half the incoherent rays mispredict.
struct RayGroup {
    static constexpr std::size_t kRays = 8;

    Ray rays[kRays];
    HitRecord records[kRays];
    bool hit[kRays] = {};
    std::size_t first = 0, size = 0;

    /// Loads the rays from `i` to the next multiple of kRays (or `end`). Groups are aligned to
    /// multiples of kRays in the whole batch, so the same rays travel together whatever the
    /// blocks are (the answers do not depend on it either way).
    template <class Real>
    void load(const RayArrays<Real>& arrays, std::size_t i, std::size_t end) {
        first = i;
        size = std::min(kRays - i % kRays, end - i);
        for (std::size_t k = 0; k < size; ++k) rays[k] = arrays.ray(i + k);
    }

    template <class SetReal>
    void nearest(const Bvh<TriangleSet<SetReal>>* bvh,
                 const Accelerator<TriangleSet<SetReal>>& structure, QueryScratch& scratch) {
        if (bvh == nullptr) {
            for (std::size_t k = 0; k < size; ++k)
                hit[k] = structure.intersect(rays[k], records[k], scratch);
        } else if (one_origin()) {
            bvh->intersect_packets({rays, size}, {records, size}, {hit, size}, scratch);
        } else {
            for (std::size_t k = 0; k < size; ++k)
                hit[k] = bvh->intersect(rays[k], records[k], scratch);
        }
    }
    template <class SetReal>
    void occluded(const Bvh<TriangleSet<SetReal>>* bvh,
                  const Accelerator<TriangleSet<SetReal>>& structure, QueryScratch& scratch) {
        if (bvh == nullptr) {
            for (std::size_t k = 0; k < size; ++k) hit[k] = structure.occluded(rays[k], scratch);
        } else if (one_origin()) {
            bvh->occluded_packets({rays, size}, {hit, size}, scratch);
        } else {
            for (std::size_t k = 0; k < size; ++k) hit[k] = bvh->occluded(rays[k], scratch);
        }
    }

private:
    bool one_origin() const {
        if (size < 2) return false;
        for (std::size_t k = 1; k < size; ++k)
            if (rays[k].origin != rays[0].origin) return false;
        return true;
    }
};

}  // namespace csgrt::detail
