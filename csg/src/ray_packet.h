#pragma once

// The batch queries' packets of rays (csg/src/batch.cpp only).

#include <algorithm>
#include <cstddef>

#include "csgrt/accel/bvh.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/csg/batch.h"

namespace csgrt::detail {

/// The rays of a block taken Bvh::kPacketRays at a time through the BVH's packet queries
/// (which answer as the single-ray queries do, bit for bit, and walk rays with one origin,
/// camera rays, as one), or one at a time through any other structure. A packet is traced
/// when one of its rays is first asked for. Only rays with one origin go through the packet
/// query: for others (shadow rays from a surface, incoherent rays) it goes ray by ray anyway,
/// after setting up every lane, and the batch's shadow rays on the armadillo cost 1,545
/// instructions a ray that way against 1,360 through the single-ray query (callgrind).
class RayPacket {
public:
    template <class Real, class SetReal>
    const HitRecord* nearest(const Bvh<TriangleSet<SetReal>>* bvh,
                             const Accelerator<TriangleSet<SetReal>>& structure,
                             const RayArrays<Real>& rays, std::size_t i, std::size_t end,
                             QueryScratch& scratch) {
        if (!holds(i)) {
            start(rays, i, end);
            if (bvh != nullptr && one_origin_) {
                bvh->intersect_packets({rays_, size_}, {records_, size_}, {hit_, size_}, scratch);
            } else {
                for (std::size_t k = 0; k < size_; ++k)
                    hit_[k] = structure.intersect(rays_[k], records_[k], scratch);
            }
        }
        return hit_[i - first_] ? &records_[i - first_] : nullptr;
    }
    template <class Real, class SetReal>
    bool occluded(const Bvh<TriangleSet<SetReal>>* bvh,
                  const Accelerator<TriangleSet<SetReal>>& structure, const RayArrays<Real>& rays,
                  std::size_t i, std::size_t end, QueryScratch& scratch) {
        if (!holds(i)) {
            start(rays, i, end);
            if (bvh != nullptr && one_origin_) {
                bvh->occluded_packets({rays_, size_}, {hit_, size_}, scratch);
            } else {
                for (std::size_t k = 0; k < size_; ++k)
                    hit_[k] = structure.occluded(rays_[k], scratch);
            }
        }
        return hit_[i - first_];
    }

private:
    static constexpr std::size_t kRays = 8;

    bool holds(std::size_t i) const { return i >= first_ && i - first_ < size_; }

    /// Packets are aligned to multiples of kRays in the whole batch, so the same rays travel
    /// together whatever the blocks are (the answers do not depend on it either way).
    template <class Real>
    void start(const RayArrays<Real>& rays, std::size_t i, std::size_t end) {
        first_ = i;
        size_ = std::min(kRays - i % kRays, end - i);
        for (std::size_t k = 0; k < size_; ++k) rays_[k] = rays.ray(i + k);
        one_origin_ = size_ > 1;
        for (std::size_t k = 1; k < size_ && one_origin_; ++k)
            one_origin_ = rays_[k].origin == rays_[0].origin;
    }

    Ray rays_[kRays];
    HitRecord records_[kRays];
    bool hit_[kRays] = {};
    bool one_origin_ = false;
    std::size_t first_ = static_cast<std::size_t>(-1), size_ = 0;
};

}  // namespace csgrt::detail
