// The BVH's packet queries (Bvh::intersect_packets, occluded_packets): up to kPacketRays rays
// through the wide tree together, with the single-ray leaf tests of bvh_traversal.h.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <new>
#include <span>
#include <type_traits>

#include "bvh_traversal.h"
#include "csgrt/accel/bvh.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"

namespace csgrt {

namespace detail {

/// The packet queries, for each layout and instruction set.
template <class Set>
struct BvhTraversal<Set>::Packets {
#if CSGRT_BVH_AVX2
    template <class NodeTest>
    static constexpr bool kAvx2Test = std::is_same_v<NodeTest, Avx2NodeTest>;
#else
    template <class NodeTest>
    static constexpr bool kAvx2Test = false;
#endif

    /// The rays of a packet: each one's float upper bound and (but for packets that
    /// PacketIntervalTest::accepts_rays takes) its box ray, and, made when first needed, its
    /// node test (the ray-by-ray walk only) and its leaf ray (at its first leaf: most camera
    /// rays reach none).
    template <class NodeTest>
    struct PacketLanes {
        using LeafRayType = LeafRayOf<kAvx2Test<NodeTest>>;
        struct Lane {
            BoxRay box;
        };
        static_assert(std::is_trivially_destructible_v<Lane> &&
                      std::is_trivially_destructible_v<NodeTest> &&
                      std::is_trivially_destructible_v<LeafRayType>);
        alignas(Lane) unsigned char lane_storage[sizeof(Lane) * Tree::kPacketRays];
        alignas(NodeTest) unsigned char test_storage[sizeof(NodeTest) * Tree::kPacketRays];
        alignas(LeafRayType) unsigned char leaf_storage[sizeof(LeafRayType) * Tree::kPacketRays];
        std::uint32_t leaf_made = 0;
        float t_max[Tree::kPacketRays];

        Lane& operator[](int r) { return reinterpret_cast<Lane*>(lane_storage)[r]; }
        const Lane& operator[](int r) const {
            return reinterpret_cast<const Lane*>(lane_storage)[r];
        }
        void make(int r, const Ray& ray) {
            new (&(*this)[r]) Lane{BoxRay(ray)};
            t_max[r] = round_up(ray.t_max);
        }
        NodeTest& test(int r) { return reinterpret_cast<NodeTest*>(test_storage)[r]; }
        void make_test(int r) { new (&test(r)) NodeTest((*this)[r].box); }
        const LeafRayType& leaf(int r, const Set& set, const Ray& ray, QueryScratch& scratch) {
            LeafRayType* leaves = reinterpret_cast<LeafRayType*>(leaf_storage);
            if ((leaf_made >> r & 1u) == 0) {
                new (&leaves[r]) LeafRayType(set, ray, scratch);
                leaf_made |= 1u << r;
            }
            return leaves[r];
        }
    };
    struct PacketEntry {
        std::uint32_t first;
        std::uint32_t count;
        /// The rays that entered the child (bit r for ray r) and the least of their entries.
        std::uint32_t rays;
        float t_enter;
    };

    /// The leaf (first, count) for each of a packet's rays in `rays` (bits), each with its own
    /// leaf test and t_max: nearest hits into best and found, or occlusion into found, a ray
    /// that is occluded leaving `open`.
    template <bool kAny, class Lanes>
    static void leaf_for_rays(const Tree& bvh, std::span<const Ray> packet, Lanes& lanes,
                              std::uint32_t rays, std::uint32_t first, std::uint32_t count,
                              HitRecord* best, bool* found, std::uint32_t& open,
                              QueryScratch& scratch) {
        TraversalCounters unused;
        for (std::uint32_t m = rays; m != 0; m &= m - 1) {
            const int r = std::countr_zero(m);
            const auto& leaf_ray = lanes.leaf(r, *bvh.set_, packet[r], scratch);
            if constexpr (kAny) {
                if (occluded_in_leaf<false>(bvh, leaf_ray, first, count, unused)) {
                    found[r] = true;
                    open &= ~(1u << r);
                }
            } else {
                found[r] |= nearest_in_leaf<false>(bvh, leaf_ray, first, count, best[r],
                                                   lanes.t_max[r], unused);
            }
        }
    }

    /// Traverses the wide tree once for up to kPacketRays rays: every node is tested against
    /// each ray that entered it, exactly as the single-ray traversal tests it (same node test,
    /// same t_max), and a ray enters a child only when its own test says so; a leaf is tested
    /// for each ray that entered it. A ray thus tests every primitive its single-ray traversal
    /// may need (the culling is the single-ray culling, only its order differs), and the tie
    /// rule of the set makes the nearest hit independent of the order: the answers are the
    /// single-ray answers bit for bit. Children are visited nearest first by the least entry
    /// of the rays that entered them. kAny: occlusion (occluded[r]); else nearest hits (best[r],
    /// found[r]). Invalid rays are left out.
    template <bool kAny, class NodeTest, int kWidth>
    static void traverse_packet(const Tree& bvh, const WideBvhNodes<kWidth>& nodes,
                                std::span<const Ray> rays, HitRecord* best, bool* found,
                                QueryScratch& scratch) {
        using Node = WideBvhNode<kWidth>;
        const int n = static_cast<int>(rays.size());
        for (int r = 0; r < n; ++r) found[r] = false;
        if (nodes.empty()) return;
        PacketLanes<NodeTest> lanes;
        std::uint32_t open = 0;
#if CSGRT_BVH_AVX2
        if constexpr (kAvx2Test<NodeTest>) {
            // The common camera packet (every ray valid, one origin), set up for all its rays
            // at once; others below, ray by ray.
            PacketIntervalTest interval;
            const PacketRayColumns columns(rays.data(), n);
            if (interval.accepts_rays(columns)) {
                for (int r = 0; r < n; ++r) {
                    lanes.t_max[r] = round_up(rays[r].t_max);
                    best[r] = HitRecord{};
                    best[r].t = rays[r].t_max;
                }
                open = (1u << n) - 1u;
                return walk_interval_packet<kAny>(bvh, rays, lanes, open, interval, best, found,
                                                  scratch, &columns);
            }
        }
#endif
        for (int r = 0; r < n; ++r) {
            lanes.make(r, rays[r]);
            if (!lanes[r].box.valid) continue;
            best[r] = HitRecord{};
            best[r].t = rays[r].t_max;
            open |= 1u << r;
        }
        if (open == 0) return;
#if CSGRT_BVH_AVX2
        if constexpr (kAvx2Test<NodeTest>) {
            PacketIntervalTest interval;
            if (interval.accepts(lanes, open)) {
                return walk_interval_packet<kAny>(bvh, rays, lanes, open, interval, best, found,
                                                  scratch, nullptr);
            }
            // Rays without a common origin (shadow rays from a surface, incoherent rays): the
            // packet's interval would hold the region between their origins, where each of
            // them tests every leaf near any of them; one at a time is faster.
            TraversalCounters unused;
            for (std::uint32_t m = open; m != 0; m &= m - 1) {
                const int r = std::countr_zero(m);
                if constexpr (kAny) {
                    found[r] = occluded<false, true>(bvh, rays[r], scratch, unused);
                } else {
                    found[r] = intersect<false, true>(bvh, rays[r], best[r], scratch, unused);
                }
            }
            return;
        }
#endif
        for (std::uint32_t m = open; m != 0; m &= m - 1) lanes.make_test(std::countr_zero(m));

        PacketEntry stack[(kWidth - 1) * kMaxDepth + 1];
        PacketEntry* top = stack;
        std::uint32_t first = 0, count = Node::kInterior, active = open;
        for (;;) {
            while (count == Node::kInterior && active != 0) {
                const Node& node = nodes[first];
                std::uint32_t child_rays[kWidth] = {};
                float child_enter[kWidth];
                std::fill_n(child_enter, kWidth, kFloatInfinity);
                unsigned entered = 0;
                for (std::uint32_t m = active; m != 0; m &= m - 1) {
                    const int r = std::countr_zero(m);
                    const NodeTest& test = lanes.test(r);
                    const float t_max = lanes.t_max[r];
                    alignas(32) float t_enter[kWidth];
                    const unsigned mask = lanes[r].box.signed_interval
                                              ? test.template hit<true>(node, t_max, t_enter)
                                              : test.template hit<false>(node, t_max, t_enter);
                    for (unsigned c = mask; c != 0; c &= c - 1) {
                        const int slot = std::countr_zero(c);
                        child_enter[slot] = std::min(child_enter[slot], t_enter[slot]);
                        child_rays[slot] |= 1u << r;
                    }
                    entered |= mask;
                }
                if (entered == 0) break;
                PacketEntry* pushed = top;
                for (unsigned c = entered; c != 0; c &= c - 1) {
                    const int slot = std::countr_zero(c);
                    *top++ = PacketEntry{node.first[slot], node.count[slot], child_rays[slot],
                                         child_enter[slot]};
                    prefetch(bvh, nodes, node.first[slot], node.count[slot]);
                }
                sort_farthest_first(pushed, top);
                --top;
                first = top->first;
                count = top->count;
                active = top->rays;
            }
            if (count != Node::kInterior && count != 0) {
                leaf_for_rays<kAny>(bvh, rays, lanes, active, first, count, best, found, open,
                                    scratch);
                if (open == 0) return;
            }
            // Each entry keeps the rays still open whose own entry may lie within their t_max
            // (their least entry does not exceed it).
            do {
                if (top == stack) return;
                --top;
                active = top->rays & open;
                for (std::uint32_t m = active; m != 0; m &= m - 1) {
                    const int r = std::countr_zero(m);
                    if (top->t_enter > lanes.t_max[r]) active &= ~(1u << r);
                }
            } while (active == 0);
            first = top->first;
            count = top->count;
        }
    }

#if CSGRT_BVH_AVX2
    /// traverse_packet with the AVX2 node test, everything inlined and compiled for AVX2.
    template <bool kAny>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET), gnu::flatten]] static void traverse_packet_avx2(
        const Tree& bvh, std::span<const Ray> rays, HitRecord* best, bool* found,
        QueryScratch& scratch) {
        traverse_packet<kAny, Avx2NodeTest>(bvh, bvh.nodes_8_, rays, best, found, scratch);
    }
#endif

#if CSGRT_BVH_AVX2
    /// The nearest hits (or occlusion) of a packet whose rays PacketIntervalTest accepts: the
    /// tree is walked once with the packet's conservative node test, as one ray would walk it,
    /// and every leaf it reaches is tested for each open ray with that ray's own leaf test and
    /// t_max. The upper bound of the walk is the largest t_max of the open rays. `columns`:
    /// the rays as PacketRayColumns when every one is open (PacketIntervalTest::accepts_rays'
    /// packets), else null.
    template <bool kAny>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] static void walk_interval_packet(
        const Tree& bvh, std::span<const Ray> rays, PacketLanes<Avx2NodeTest>& lanes,
        std::uint32_t open, const PacketIntervalTest& test, HitRecord* best, bool* found,
        QueryScratch& scratch, const PacketRayColumns* columns) {
        TraversalCounters unused;
        auto largest_t_max = [&] {
            float t_max = -kFloatInfinity;
            for (std::uint32_t m = open; m != 0; m &= m - 1)
                t_max = std::max(t_max, lanes.t_max[std::countr_zero(m)]);
            return t_max;
        };
        if constexpr (kBlockSet) {
            if (!bvh.leaf_triangles_.empty()) {
                // Ray-parallel leaves, when the rays share the triangle test's axes.
                typename Set::PreparedRay prepared[Tree::kPacketRays];
                PacketTriangleRays triangle_rays;
                // All the rays open (accepts_rays' packets): their prepared rays eight at a
                // time; else ray by ray.
                auto accepted = [&] {
                    if (columns != nullptr)
                        return triangle_rays.accepts_rays(*columns, static_cast<int>(rays.size()),
                                                          prepared);
                    for (std::uint32_t m = open; m != 0; m &= m - 1) {
                        const int r = std::countr_zero(m);
                        prepared[r] = bvh.set_->prepare(rays[r], scratch);
                    }
                    return triangle_rays.accepts(prepared, open);
                };
                if (accepted()) {
                    // The triangle of lane `lane` of the group of kWidth lanes at `group`
                    // against every open ray, for rays whose test axis z is kAxisZ.
                    auto test_lane = [&]<int kAxisZ, std::ptrdiff_t kWidth>(
                                         const float* group, const float(&relative)[9][8],
                                         std::ptrdiff_t lane) {
                        alignas(32) float sheared[9][8];
                        unsigned candidates = triangle_rays.template candidates<kAxisZ>(
                            relative, lane, open, sheared);
                        while (candidates != 0) {
                            const int r = std::countr_zero(candidates);
                            candidates &= candidates - 1;
                            TriangleSet<float>::ShearedTriangle triangle;
                            for (int k = 0; k < 3; ++k) {
                                triangle.x[k] = sheared[k][r];
                                triangle.y[k] = sheared[3 + k][r];
                                triangle.z[k] = sheared[6 + k][r];
                            }
                            double t, b1, b2;
                            if (!TriangleSet<float>::hit_sheared(triangle, prepared[r].shear_z, t,
                                                                 b1, b2)) {
                                continue;
                            }
                            if constexpr (kAny) {
                                if (t >= prepared[r].t_min && t <= prepared[r].t_max) {
                                    found[r] = true;
                                    open &= ~(1u << r);
                                }
                            } else if (Set::keep_nearest(
                                           std::bit_cast<std::uint32_t>(group[9 * kWidth + lane]),
                                           t, b1, b2, prepared[r], best[r])) {
                                found[r] = true;
                                lanes.t_max[r] = round_up(best[r].t);
                            }
                        }
                    };
                    // The leaf's groups of lanes (BvhLeafTriangles), lane by lane; true when no
                    // ray is left open.
                    auto test_leaf = [&]<int kAxisZ>(std::uint32_t first, std::uint32_t count) {
                        const float* group =
                            bvh.leaf_triangles_.lanes.data() + kLaneFloats * kBlockLanes * first;
                        std::uint32_t left = count;
                        for (; left > kBlockLanes; group += 2 * kBlockLanes * kLaneFloats) {
                            const std::uint32_t used = std::min(left, 2 * kBlockLanes);
                            left -= used;
                            alignas(32) float relative[9][8];
                            triangle_rays.template relative_corners<2 * kBlockLanes>(group,
                                                                                     relative);
                            for (std::uint32_t lane = 0; lane < used; ++lane) {
                                test_lane.template operator()<kAxisZ, 2 * kBlockLanes>(
                                    group, relative, lane);
                                if (open == 0) return true;
                            }
                        }
                        if (left == 0) return false;
                        alignas(32) float relative[9][8];
                        triangle_rays.template relative_corners<kBlockLanes>(group, relative);
                        for (std::uint32_t lane = 0; lane < left; ++lane) {
                            test_lane.template operator()<kAxisZ, kBlockLanes>(group, relative,
                                                                               lane);
                            if (open == 0) return true;
                        }
                        return false;
                    };
                    auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
                        bool done;
                        switch (triangle_rays.axis[2]) {
                            case 0:
                                done = test_leaf.template operator()<0>(first, count);
                                break;
                            case 1:
                                done = test_leaf.template operator()<1>(first, count);
                                break;
                            default:
                                done = test_leaf.template operator()<2>(first, count);
                                break;
                        }
                        if (done) return true;
                        t_max = largest_t_max();
                        return false;
                    };
                    walk_wide<false, false, !kAny>(bvh, bvh.nodes_8_, test, largest_t_max(), unused,
                                                   leaf);
                    return;
                }
            }
        }
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
            leaf_for_rays<kAny>(bvh, rays, lanes, open, first, count, best, found, open, scratch);
            t_max = largest_t_max();
            return open == 0;
        };
        walk_wide<false, false, !kAny>(bvh, bvh.nodes_8_, test, largest_t_max(), unused, leaf);
    }
#endif

    /// Up to kPacketRays rays through the wide tree (width 4 or 8).
    template <bool kAny>
    static void packet(const Tree& bvh, std::span<const Ray> rays, HitRecord* best, bool* found,
                       QueryScratch& scratch) {
        if (bvh.config_.width == 8) {
#if CSGRT_BVH_AVX2
            if (bvh.use_avx2_) return traverse_packet_avx2<kAny>(bvh, rays, best, found, scratch);
#endif
            return traverse_packet<kAny, SseNodeTest<8>>(bvh, bvh.nodes_8_, rays, best, found,
                                                         scratch);
        }
        traverse_packet<kAny, SseNodeTest<4>>(bvh, bvh.nodes_4_, rays, best, found, scratch);
    }
};

}  // namespace detail

template <class Set>
template <bool kAny>
std::size_t Bvh<Set>::trace_packets(std::span<const Ray> rays, std::span<HitRecord> records,
                                    std::span<bool> hit, QueryScratch& scratch) const {
    std::size_t hits = 0;
    // Instance paths of a ShapeSet's hits live in the scratch of one query at a time, and the
    // binary tree has no packet traversal: those go one ray at a time.
    if (std::is_same_v<Set, ShapeSet> || config_.width == 2 || set_ == nullptr) {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if constexpr (kAny) {
                hit[i] = this->occluded(rays[i], scratch);
            } else {
                hit[i] = this->intersect(rays[i], records[i], scratch);
            }
            hits += hit[i] ? 1 : 0;
        }
        return hits;
    }
    if constexpr (!std::is_same_v<Set, ShapeSet>) {
        // Left unconstructed (HitRecord is an aggregate, so the bytes hold its objects): the
        // packet query writes a valid ray's record before it reads it, and never reads an
        // invalid ray's. Constructing all eight cost the batch's groups of eight rays 8
        // instructions a camera ray.
        alignas(HitRecord) unsigned char best_storage[sizeof(HitRecord) * kPacketRays];
        HitRecord* best = reinterpret_cast<HitRecord*>(best_storage);
        bool found[kPacketRays];
        for (std::size_t begin = 0; begin < rays.size(); begin += kPacketRays) {
            const std::size_t n = std::min(kPacketRays, rays.size() - begin);
            detail::BvhTraversal<Set>::Packets::template packet<kAny>(*this, rays.subspan(begin, n),
                                                                      best, found, scratch);
            for (std::size_t r = 0; r < n; ++r) {
                hit[begin + r] = found[r];
                if constexpr (!kAny) {
                    if (found[r]) records[begin + r] = best[r];
                }
                hits += found[r] ? 1 : 0;
            }
        }
    }
    return hits;
}

template <class Set>
std::size_t Bvh<Set>::intersect_packets(std::span<const Ray> rays, std::span<HitRecord> records,
                                        std::span<bool> hit, QueryScratch& scratch) const {
    require(records.size() == rays.size(), "Bvh::intersect_packets", "records.size()",
            "rays.size()", records.size());
    require(hit.size() == rays.size(), "Bvh::intersect_packets", "hit.size()", "rays.size()",
            hit.size());
    return trace_packets<false>(rays, records, hit, scratch);
}

template <class Set>
std::size_t Bvh<Set>::occluded_packets(std::span<const Ray> rays, std::span<bool> occluded,
                                       QueryScratch& scratch) const {
    require(occluded.size() == rays.size(), "Bvh::occluded_packets", "occluded.size()",
            "rays.size()", occluded.size());
    return trace_packets<true>(rays, {}, occluded, scratch);
}

// The packet queries of each set a Bvh is built over.
#define CSGRT_INSTANTIATE_PACKETS(Set)                                                         \
    template std::size_t Bvh<Set>::intersect_packets(std::span<const Ray>, std::span<HitRecord>, \
                                                     std::span<bool>, QueryScratch&) const;     \
    template std::size_t Bvh<Set>::occluded_packets(std::span<const Ray>, std::span<bool>,       \
                                                    QueryScratch&) const;
CSGRT_INSTANTIATE_PACKETS(TriangleSet<float>)
CSGRT_INSTANTIATE_PACKETS(TriangleSet<double>)
CSGRT_INSTANTIATE_PACKETS(ShapeSet)
#undef CSGRT_INSTANTIATE_PACKETS

}  // namespace csgrt
