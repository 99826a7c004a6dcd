#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <span>
#include <thread>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/bvh.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/query_scratch.h"
#include "csgrt/core/ray.h"

namespace csgrt::bench {

/// Something the benchmark can trace a batch of rays through: one of csgrt's structures, CGAL's
/// AABB tree or Embree. One virtual call per batch; the loop over the rays is inside.
class Tracer {
public:
    virtual ~Tracer() = default;
    /// The nearest-hit query on every ray; returns how many rays hit.
    virtual std::size_t nearest(std::span<const Ray> rays, QueryScratch& scratch) const = 0;
    /// The occlusion (any-hit) query on every ray; returns how many rays are occluded.
    virtual std::size_t occluded(std::span<const Ray> rays, QueryScratch& scratch) const = 0;
    /// Counted nearest or occlusion queries on every ray (structures only; false otherwise).
    virtual bool count(std::span<const Ray> /*rays*/, bool /*occlusion*/,
                       TraversalCounters& /*counters*/) const {
        return false;
    }
};

/// A csgrt structure as a Tracer.
template <class Set>
class AcceleratorTracer final : public Tracer {
public:
    explicit AcceleratorTracer(const Accelerator<Set>& structure) : structure_(structure) {}

    std::size_t nearest(std::span<const Ray> rays, QueryScratch& scratch) const override {
        std::size_t hits = 0;
        for (const Ray& ray : rays) {
            HitRecord record;
            hits += structure_.intersect(ray, record, scratch) ? 1 : 0;
        }
        return hits;
    }
    std::size_t occluded(std::span<const Ray> rays, QueryScratch& scratch) const override {
        std::size_t hits = 0;
        for (const Ray& ray : rays) hits += structure_.occluded(ray, scratch) ? 1 : 0;
        return hits;
    }
    bool count(std::span<const Ray> rays, bool occlusion,
               TraversalCounters& counters) const override {
        QueryScratch scratch;
        for (const Ray& ray : rays) {
            HitRecord record;
            if (occlusion) {
                structure_.occluded_counted(ray, scratch, counters);
            } else {
                structure_.intersect_counted(ray, record, scratch, counters);
            }
        }
        return true;
    }

private:
    const Accelerator<Set>& structure_;
};

/// csgrt's BVH tracing Bvh::kPacketRays consecutive rays together (intersect_packets,
/// occluded_packets), the answers bit-identical to the single-ray queries.
class BvhPacketTracer final : public Tracer {
public:
    explicit BvhPacketTracer(const Bvh<TriangleSet<float>>& bvh) : bvh_(bvh) {}

    std::size_t nearest(std::span<const Ray> rays, QueryScratch& scratch) const override {
        std::size_t hits = 0;
        HitRecord records[kChunk];
        bool hit[kChunk];
        for (std::size_t begin = 0; begin < rays.size(); begin += kChunk) {
            const std::size_t n = std::min(kChunk, rays.size() - begin);
            hits += bvh_.intersect_packets(rays.subspan(begin, n), std::span(records, n),
                                           std::span(hit, n), scratch);
        }
        return hits;
    }
    std::size_t occluded(std::span<const Ray> rays, QueryScratch& scratch) const override {
        std::size_t hits = 0;
        bool occluded[kChunk];
        for (std::size_t begin = 0; begin < rays.size(); begin += kChunk) {
            const std::size_t n = std::min(kChunk, rays.size() - begin);
            hits += bvh_.occluded_packets(rays.subspan(begin, n), std::span(occluded, n), scratch);
        }
        return hits;
    }

private:
    static constexpr std::size_t kChunk = 256;
    const Bvh<TriangleSet<float>>& bvh_;
};

/// Runs `trace(begin, end, scratch)` over [0, count) on `threads` threads (the calling thread
/// and threads - 1 std::threads), handing out blocks of rays from a shared counter so that
/// threads finishing early take more; each thread has its own QueryScratch. Returns the sum
/// of what the calls return. One thread runs inline, so its CPU time is the work's.
template <class Trace>
std::size_t for_ray_blocks(std::size_t count, int threads, const Trace& trace) {
    if (threads <= 1) {
        QueryScratch scratch;
        return trace(std::size_t{0}, count, scratch);
    }
    // Blocks small enough to balance, large enough that the shared counter is not contended.
    constexpr std::size_t kBlock = 256;
    std::atomic<std::size_t> next{0};
    std::atomic<std::size_t> total{0};
    auto worker = [&] {
        QueryScratch scratch;
        std::size_t sum = 0;
        for (;;) {
            const std::size_t begin = next.fetch_add(kBlock, std::memory_order_relaxed);
            if (begin >= count) break;
            sum += trace(begin, std::min(begin + kBlock, count), scratch);
        }
        total.fetch_add(sum, std::memory_order_relaxed);
    };
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(threads - 1));
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (std::thread& thread : pool) thread.join();
    return total.load();
}

/// Traces `rays` through `tracer` (nearest or occlusion) on `threads` threads; returns the
/// number of hits.
inline std::size_t trace_all(const Tracer& tracer, std::span<const Ray> rays, bool occlusion,
                             int threads) {
    return for_ray_blocks(
        rays.size(), threads, [&](std::size_t begin, std::size_t end, QueryScratch& scratch) {
            const auto block = rays.subspan(begin, end - begin);
            return occlusion ? tracer.occluded(block, scratch) : tracer.nearest(block, scratch);
        });
}

}  // namespace csgrt::bench
