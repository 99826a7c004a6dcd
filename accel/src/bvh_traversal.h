#pragma once

// The BVH's single-ray queries: the traversal of the binary and wide trees (SSE and AVX2 node
// tests), the leaf visitor over triangle blocks and index leaves, and the nearest, any and all
// hit queries built from them. Internal to accel/src: bvh_traversal.cpp compiles the queries,
// and bvh_packet.cpp reuses the leaf tests and the wide walk for packets. Everything here is a
// template of a header, so each of those sources inlines what it calls exactly as one source
// would (run_avx2 and traverse_packet_avx2 flatten it all into AVX2 code).

#include <algorithm>
#include <bit>
#include <cstdint>
#include <new>
#include <type_traits>
#include <vector>

#include "bvh_leaf.h"
#include "bvh_ray.h"
#include "csgrt/accel/bvh.h"
#include "csgrt/accel/triangle_set.h"

namespace csgrt::detail {

/// The single-ray queries, for each layout and instruction set; a friend of Bvh.
template <class Set>
struct BvhTraversal {
    using Tree = Bvh<Set>;
    static constexpr bool kBlockSet = kBlockLeaves<Set>;

    struct BinaryEntry {
        std::uint32_t node;
        float t_enter;
    };
    struct WideEntry {
        std::uint32_t first;
        std::uint32_t count;
        float t_enter;
    };

    /// Visits every leaf the ray may hit within [t_min, t_max], nearest entry first, and
    /// returns whether the ray is valid (is_valid; an invalid ray visits nothing). `leaf` is
    /// called as leaf(first, count, t_max) with the leaf's reference (see Bvh::binary_nodes)
    /// and the float upper bound of the interval, which it may lower; it returns true to stop.
    /// kAvx2: the 8-wide tree with the AVX2 node tests (run_avx2 only).
    template <bool kCount, bool kAvx2, bool kNearestFirst = true, class Leaf>
    static bool traverse(const Tree& bvh, const Ray& ray, TraversalCounters& counters, Leaf& leaf) {
#if CSGRT_BVH_AVX2
        if constexpr (kAvx2) {
            // Nearly every ray takes the fused test; the others (a signed interval, a zero
            // direction component, an extreme origin or direction) take Avx2NodeTest's signed
            // form, which is conservative for t_min >= 0 too (it only widens more).
            Avx2FusedNodeTest fused;
            switch (fused.make(ray)) {
                case Avx2FusedNodeTest::Setup::kTaken:
                    if (!bvh.nodes_8_.empty()) {
                        walk_wide<kCount, false, kNearestFirst>(
                            bvh, bvh.nodes_8_, fused, round_up(ray.t_max), counters, leaf);
                    }
                    return true;
                case Avx2FusedNodeTest::Setup::kInvalid:
                    return false;
                case Avx2FusedNodeTest::Setup::kGeneral:
                    break;
            }
            const BoxRay box_ray(ray);
            if (!box_ray.valid) return false;
            traverse_wide<kCount, true, kNearestFirst, Avx2NodeTest>(bvh, bvh.nodes_8_, box_ray,
                                                                     ray.t_max, counters, leaf);
            return true;
        }
#endif
        const BoxRay box_ray(ray);
        if (!box_ray.valid) return false;
        // The SSE node test of a wide tree, in its signed form only for rays that need it.
        auto traverse_sse = [&]<int kWidth>(const WideBvhNodes<kWidth>& nodes) {
            if (box_ray.signed_interval) {
                traverse_wide<kCount, true, kNearestFirst, SseNodeTest<kWidth>>(
                    bvh, nodes, box_ray, ray.t_max, counters, leaf);
            } else {
                traverse_wide<kCount, false, kNearestFirst, SseNodeTest<kWidth>>(
                    bvh, nodes, box_ray, ray.t_max, counters, leaf);
            }
        };
        if (bvh.config_.width == 8) {
            traverse_sse(bvh.nodes_8_);
        } else if (bvh.config_.width == 4) {
            traverse_sse(bvh.nodes_4_);
        } else if (box_ray.signed_interval) {
            traverse_binary<kCount, true>(bvh, box_ray, ray.t_max, counters, leaf);
        } else {
            traverse_binary<kCount, false>(bvh, box_ray, ray.t_max, counters, leaf);
        }
        return true;
    }

    /// One query of kind kKind, with the AVX2 node test when kAvx2.
    template <QueryKind kKind, bool kCount, bool kAvx2>
    static bool run(const Tree& bvh, const Ray& ray, QueryAnswer<kKind>& answer,
                    QueryScratch& scratch, TraversalCounters& counters) {
        if constexpr (kKind == QueryKind::kNearest) {
            return intersect<kCount, kAvx2>(bvh, ray, answer, scratch, counters);
        } else if constexpr (kKind == QueryKind::kAny) {
            return occluded<kCount, kAvx2>(bvh, ray, scratch, counters);
        } else {
            const std::size_t before = answer.size();
            all_hits<kCount, kAvx2>(bvh, ray, answer, scratch, counters);
            return answer.size() > before;
        }
    }

#if CSGRT_BVH_AVX2
    /// The whole query compiled for AVX2: `flatten` inlines everything it calls (the ray's
    /// set-up, the traversal, the leaf visitor, the triangle test), so all of it is AVX2 code,
    /// here and nowhere else, with no call between the set-up and the traversal.
    template <QueryKind kKind, bool kCount>
    [[gnu::target(CSGRT_BVH_AVX2_TARGET), gnu::flatten]] static bool run_avx2(
        const Tree& bvh, const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
        TraversalCounters& counters) {
        return run<kKind, kCount, true>(bvh, ray, answer, scratch, counters);
    }
#endif

#if CSGRT_BVH_AVX2
    /// How many of a wide node's hit children (bits of `hit`, entered at t_enter, 32-byte
    /// aligned) go below child `slot` on the stack: those entered farther, and those entered as
    /// far in a lower slot. Every hit child's distance is a number (the node test's comparison
    /// is false for NaN), so the places are a permutation. Inlined into AVX2 code only (the
    /// node tests' kAvx2), where the load is made once for all the children.
    [[gnu::target(CSGRT_BVH_AVX2_TARGET)]] static int entries_below(const float* t_enter,
                                                                    unsigned hit, int slot) {
        const __m256 entries = _mm256_load_ps(t_enter), own = _mm256_set1_ps(t_enter[slot]);
        const unsigned farther =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(entries, own, _CMP_GT_OQ)));
        const unsigned as_far =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(entries, own, _CMP_EQ_OQ)));
        return std::popcount(hit & (farther | (as_far & ((1u << slot) - 1u))));
    }
#endif

    /// Orders the entries a node just pushed, [pushed, top), farthest entry first, so that the
    /// nearest is popped next (an insertion sort: at most a node's width of them; entries
    /// entered as far keep the order they were pushed in). Any entry type with a t_enter.
    template <class Entry>
    static void sort_farthest_first(Entry* pushed, Entry* top) {
        for (Entry* i = pushed + 1; i != top; ++i) {
            const Entry entry = *i;
            Entry* j = i;
            for (; j != pushed && (j - 1)->t_enter < entry.t_enter; --j) *j = *(j - 1);
            *j = entry;
        }
    }

    /// Starts loading what a leaf or node the traversal will come back to needs: a node's
    /// cache lines, a leaf's first block, a one-primitive leaf's primitive, or a leaf's
    /// indices.
    template <int kWidth>
    static void prefetch([[maybe_unused]] const Tree& bvh,
                         [[maybe_unused]] const WideBvhNodes<kWidth>& nodes,
                         [[maybe_unused]] std::uint32_t first,
                         [[maybe_unused]] std::uint32_t count) {
#if defined(__SSE2__)
        auto fetch = [](const void* address, std::size_t bytes) {
            const char* p = static_cast<const char*>(address);
            for (std::size_t line = 0; line < bytes; line += 64)
                _mm_prefetch(p + line, _MM_HINT_T0);
        };
        if (count == WideBvhNode<kWidth>::kInterior) {
            fetch(&nodes[first], sizeof(WideBvhNode<kWidth>));
        } else if (!bvh.leaf_triangles_.empty()) {
            // The first three lines of the leaf's lanes: all of a group of four.
            fetch(bvh.leaf_triangles_.lanes.data() + kLaneFloats * kBlockLanes * first, 192);
        } else if (count == 1) {
            if constexpr (requires { bvh.set_->corner(std::size_t{0}, 0); }) {
                const auto* corners = &bvh.set_->corner(first, 0);
                fetch(corners, 3 * sizeof(*corners));
            }
        } else {
            fetch(&bvh.indices_[first], sizeof(std::uint32_t));
        }
#endif
    }

    template <bool kCount, bool kSigned, class Leaf>
    static void traverse_binary(const Tree& bvh, const BoxRay& box_ray, double ray_t_max,
                                TraversalCounters& counters, Leaf& leaf) {
        const auto& nodes = bvh.binary_nodes_;
        if (nodes.empty()) return;
        float t_max = round_up(ray_t_max);
        float t_enter;
        if constexpr (kCount) ++counters.boxes_tested;
        if (!hit_box<kSigned>(nodes[0], box_ray, t_max, t_enter)) return;

        // Each level pushes at most the far child, so the depth bounds the stack.
        BinaryEntry stack[kMaxDepth + 1];
        int size = 0;
        std::uint32_t index = 0;
        for (;;) {
            const BvhNode& node = nodes[index];
            if constexpr (kCount) ++counters.nodes_visited;
            if (node.is_leaf()) {
                if (leaf(node.offset, node.count, t_max)) return;
            } else {
                if constexpr (kCount) counters.boxes_tested += 2;
                float t_left, t_right;
                const bool left = hit_box<kSigned>(nodes[node.offset], box_ray, t_max, t_left);
                const bool right =
                    hit_box<kSigned>(nodes[node.offset + 1], box_ray, t_max, t_right);
                if (left && right) {
                    const bool right_first = t_right < t_left;
                    stack[size++] = {node.offset + (right_first ? 0 : 1),
                                     right_first ? t_left : t_right};
                    index = node.offset + (right_first ? 1 : 0);
                    continue;
                }
                if (left || right) {
                    index = node.offset + (left ? 0 : 1);
                    continue;
                }
            }
            // Skip entries whose subtree starts beyond the nearest hit found since they were
            // pushed.
            do {
                if (size == 0) return;
                --size;
            } while (stack[size].t_enter > t_max);
            index = stack[size].node;
        }
    }

    template <bool kCount, bool kSigned, bool kNearestFirst, class NodeTest, int kWidth, class Leaf>
    static void traverse_wide(const Tree& bvh, const WideBvhNodes<kWidth>& nodes,
                              const BoxRay& box_ray, double ray_t_max, TraversalCounters& counters,
                              Leaf& leaf) {
        if (nodes.empty()) return;
        const NodeTest test(box_ray);
        walk_wide<kCount, kSigned, kNearestFirst>(bvh, nodes, test, round_up(ray_t_max), counters,
                                                  leaf);
    }

    /// traverse_wide with its node test made: `test.hit<kSigned>(node, t_max, t_enter)` gives
    /// the mask of the children to enter (a single ray's, or a packet's conservative one).
    template <bool kCount, bool kSigned, bool kNearestFirst = true, class NodeTest, int kWidth,
              class Leaf>
    static void walk_wide(const Tree& bvh, const WideBvhNodes<kWidth>& nodes, const NodeTest& test,
                          float t_max, TraversalCounters& counters, Leaf& leaf) {
        using Node = WideBvhNode<kWidth>;

        // Each level pushes at most kWidth - 1 children.
        WideEntry stack[(kWidth - 1) * kMaxDepth + 1];
        WideEntry* top = stack;
        std::uint32_t first = 0, count = Node::kInterior;
        alignas(32) float t_enter[kWidth];
        for (;;) {
            // A small node test is copied for each descent (NodeTest::kCopyForDescent): that
            // keeps its values in registers while descending, where otherwise they would stay
            // live (and, for want of registers, in memory) across the leaf tests between
            // descents. The empty asm says that `test` may have changed, so that the compiler
            // reads it afresh rather than reuse the values read for the previous descent.
            if constexpr (NodeTest::kCopyForDescent) asm("" : : "r"(&test) : "memory");
            const std::conditional_t<NodeTest::kCopyForDescent, NodeTest, const NodeTest&>
                descent_test = test;
            // Descend through interior nodes, nearest child first, until a leaf or a dead end.
            while (count == Node::kInterior) {
                const Node& node = nodes[first];
                if constexpr (kCount) {
                    ++counters.nodes_visited;
                    counters.boxes_tested += kWidth;
                }
                unsigned mask = descent_test.template hit<kSigned>(node, t_max, t_enter);
                if (mask == 0) break;
                const int nearest = std::countr_zero(mask);
                mask &= mask - 1;
                first = node.first[nearest];
                count = node.count[nearest];
                if (mask == 0) continue;
                if ((mask & (mask - 1)) == 0) {
                    // Two children (the common case): push the farther, take the nearer; at
                    // equal entries the later slot, as the ordering below would.
                    const int other = std::countr_zero(mask);
                    if (t_enter[other] <= t_enter[nearest]) {
                        *top++ = WideEntry{first, count, t_enter[nearest]};
                        first = node.first[other];
                        count = node.count[other];
                    } else {
                        *top++ = WideEntry{node.first[other], node.count[other], t_enter[other]};
                    }
                    prefetch(bvh, nodes, (top - 1)->first, (top - 1)->count);
                    continue;
                }
                if constexpr (!kNearestFirst) {
                    // Any hit will do (occlusion, every hit): the others wait in slot order.
                    do {
                        const int slot = std::countr_zero(mask);
                        mask &= mask - 1;
                        *top++ = WideEntry{node.first[slot], node.count[slot], t_enter[slot]};
                        prefetch(bvh, nodes, node.first[slot], node.count[slot]);
                    } while (mask != 0);
                    continue;
                }
                // Three or more children: push them all, nearest on top, and take it. Those
                // left waiting are fetched while the nearest one is traversed.
#if CSGRT_BVH_AVX2
                if constexpr (NodeTest::kAvx2) {
                    // Each child straight to its place: below it go the children entered
                    // farther, and those entered as far in a lower slot (the order the sort
                    // below makes), two vector compares and a popcount a child where the sort
                    // takes a branch a comparison that the ray's direction decides.
                    const unsigned hit = mask | (1u << nearest);
                    for (unsigned rest = hit; rest != 0; rest &= rest - 1) {
                        const int slot = std::countr_zero(rest);
                        const int place = entries_below(t_enter, hit, slot);
                        top[place] = WideEntry{node.first[slot], node.count[slot], t_enter[slot]};
                        prefetch(bvh, nodes, node.first[slot], node.count[slot]);
                    }
                    top += std::popcount(hit) - 1;
                    first = top->first;
                    count = top->count;
                    continue;
                }
#endif
                WideEntry* pushed = top;
                *top++ = WideEntry{first, count, t_enter[nearest]};
                prefetch(bvh, nodes, first, count);
                do {
                    const int slot = std::countr_zero(mask);
                    mask &= mask - 1;
                    *top++ = WideEntry{node.first[slot], node.count[slot], t_enter[slot]};
                    prefetch(bvh, nodes, node.first[slot], node.count[slot]);
                } while (mask != 0);
                sort_farthest_first(pushed, top);
                --top;
                first = top->first;
                count = top->count;
            }
            // An unused slot (count 0) is entered only by rays the float test cannot
            // represent, which enter every box.
            if (count != Node::kInterior && count != 0) {
                if constexpr (kCount) ++counters.nodes_visited;
                if (leaf(first, count, t_max)) return;
            }
            // Skip entries whose subtree starts beyond the nearest hit found since they were
            // pushed.
            do {
                if (top == stack) return;
                --top;
            } while (top->t_enter > t_max);
            first = top->first;
            count = top->count;
        }
    }

    /// A ray as the leaves test it: the set's prepared ray and, for block leaves, its SIMD
    /// forms, made once per query; kWide adds the 8-lane form of the AVX2 query.
    struct NoBlockRay {
        template <class Any>
        explicit NoBlockRay(const Any&) {}
    };
    using LeafBlockRay = std::conditional_t<kBlockSet, BlockRay, NoBlockRay>;
#if CSGRT_BVH_AVX2
    using WideBlockRay = std::conditional_t<kBlockSet, Avx2BlockRay, NoBlockRay>;
#else
    using WideBlockRay = NoBlockRay;
#endif
    template <bool kWide>
    struct LeafRayOf {
        static constexpr bool kPairs = kWide && kBlockSet && CSGRT_BVH_AVX2;
        typename Set::PreparedRay prepared;
        LeafBlockRay block;
        [[no_unique_address]] std::conditional_t<kWide, WideBlockRay, NoBlockRay> wide;

        LeafRayOf(const Set& set, const Ray& ray, QueryScratch& scratch)
            : prepared(set.prepare(ray, scratch)), block(prepared), wide(block) {}
    };
    using LeafRay = LeafRayOf<false>;

    /// A triangle of a block that the set's test reports as hit on the ray's line, at t with
    /// the barycentrics b1, b2 of corners 1 and 2.
    struct BlockCandidate {
        std::uint32_t index;
        double t, b1, b2;
        const typename Set::PreparedRay& ray;

        bool keep_nearest(HitRecord& record) const {
            return Set::keep_nearest(index, t, b1, b2, ray, record);
        }
        bool occludes() const { return t >= ray.t_min && t <= ray.t_max; }
    };
    /// A primitive of an index leaf, not yet tested: the set's own queries test it.
    struct PrimitiveCandidate {
        const Set& set;
        std::uint32_t index;
        const typename Set::PreparedRay& ray;

        bool keep_nearest(HitRecord& record) const { return set.intersect(index, ray, record); }
        bool occludes() const { return set.occluded(index, ray); }
    };

    /// Calls visit(candidate) for each primitive of the leaf (first, count) that may be hit,
    /// until it returns true; returns whether it did. A candidate answers keep_nearest(record)
    /// (the set's intersect: the hit in [t_min, record.t] that beats record under the tie
    /// rule) and occludes() (the set's occluded). Block leaves test four triangles at once and
    /// hand on only those hit on the ray's line; index leaves hand on every primitive.
    template <bool kCount, bool kWide, class Visit>
    static bool for_each_hit(const Tree& bvh, const LeafRayOf<kWide>& ray, std::uint32_t first,
                             std::uint32_t count, TraversalCounters& counters, Visit&& visit) {
        if constexpr (kBlockSet) {
            if (!bvh.leaf_triangles_.empty()) {
                switch (ray.prepared.axis_z) {
                    case 0:
                        return for_each_hit_in_lanes<kCount, kWide, 0>(bvh, ray, first, count,
                                                                       counters, visit);
                    case 1:
                        return for_each_hit_in_lanes<kCount, kWide, 1>(bvh, ray, first, count,
                                                                       counters, visit);
                    default:
                        return for_each_hit_in_lanes<kCount, kWide, 2>(bvh, ray, first, count,
                                                                       counters, visit);
                }
            }
        }
        const Set& set = *bvh.set_;
        if (count == 1) {
            if constexpr (kCount) ++counters.primitives_tested;
            return visit(PrimitiveCandidate{set, first, ray.prepared});
        }
        const std::uint32_t* indices = bvh.indices_.data() + first;
        for (std::uint32_t i = 0; i != count; ++i) {
            if constexpr (kCount) ++counters.primitives_tested;
            if (visit(PrimitiveCandidate{set, indices[i], ray.prepared})) return true;
        }
        return false;
    }

    /// for_each_hit on a leaf of triangle lanes (BvhLeafTriangles), for rays whose test axis z
    /// is kAxisZ.
    template <bool kCount, bool kWide, int kAxisZ, class Visit>
    static bool for_each_hit_in_lanes(const Tree& bvh, const LeafRayOf<kWide>& ray,
                                      std::uint32_t first, std::uint32_t count,
                                      TraversalCounters& counters, Visit& visit) {
        // The candidate lanes of four, finished by BlockHits (or by the set's test where
        // an edge function is zero) and handed to visit; `primitives` holds the four
        // lanes' triangle indices as float bits.
        auto visit_lanes = [&](const float* primitives, const ShearedBlock& sheared,
                               unsigned candidates, unsigned zeros) {
            const BlockHits hits(sheared, ray.prepared.shear_z);
            do {
                const int lane = std::countr_zero(candidates);
                candidates &= candidates - 1;
                double t = hits.t[lane], b1 = hits.b1[lane], b2 = hits.b2[lane];
                if ((zeros >> lane & 1u) != 0 &&
                    !TriangleSet<float>::hit_sheared(sheared.lane(lane), ray.prepared.shear_z, t,
                                                     b1, b2)) {
                    continue;
                }
                const auto index = std::bit_cast<std::uint32_t>(primitives[lane]);
                if (visit(BlockCandidate{index, t, b1, b2, ray.prepared})) return true;
            } while (candidates != 0);
            return false;
        };
        // Groups of eight lanes while more than four are left, then one of four
        // (BvhLeafTriangles).
        const float* group = bvh.leaf_triangles_.lanes.data() + kLaneFloats * kBlockLanes * first;
        std::uint32_t left = count;
        for (; left > kBlockLanes; group += 8 * kLaneFloats) {
            const std::uint32_t lanes = std::min(left, 2 * kBlockLanes);
            left -= lanes;
            if constexpr (kCount) counters.primitives_tested += lanes;
            const unsigned used = (1u << lanes) - 1u;
            if constexpr (LeafRayOf<kWide>::kPairs) {
                // Both halves in one 8-lane step, each split off only when it holds a
                // candidate.
                const Avx2ShearedLanes sheared = ray.wide.template shear<kAxisZ>(group);
                const unsigned candidates = sheared.candidates() & used;
                if ((candidates & 0xfu) != 0 &&
                    visit_lanes(group + 72, sheared.half(0), candidates & 0xfu,
                                sheared.zeros & 0xfu)) {
                    return true;
                }
                if ((candidates >> 4) != 0 &&
                    visit_lanes(group + 76, sheared.half(1), candidates >> 4, sheared.zeros >> 4)) {
                    return true;
                }
            } else {
                for (int half = 0; half < 2; ++half) {
                    ShearedBlock sheared;
                    unsigned zeros;
                    const unsigned candidates =
                        ray.block.template candidates<kAxisZ, 8>(group + 4 * half, sheared, zeros) &
                        (used >> (4 * half));
                    if (candidates != 0 &&
                        visit_lanes(group + 72 + 4 * half, sheared, candidates, zeros)) {
                        return true;
                    }
                }
            }
        }
        if (left != 0) {
            if constexpr (kCount) counters.primitives_tested += left;
            ShearedBlock sheared;
            unsigned zeros;
            const unsigned candidates =
                ray.block.template candidates<kAxisZ, 4>(group, sheared, zeros) &
                ((1u << left) - 1u);
            if (candidates != 0 && visit_lanes(group + 36, sheared, candidates, zeros)) return true;
        }
        return false;
    }

    /// The nearest-hit leaf test: keeps the leaf's best hit in `best` and lowers t_max to it.
    template <bool kCount, bool kWide>
    static bool nearest_in_leaf(const Tree& bvh, const LeafRayOf<kWide>& ray, std::uint32_t first,
                                std::uint32_t count, HitRecord& best, float& t_max,
                                TraversalCounters& counters) {
        bool hit = false;
        for_each_hit<kCount>(bvh, ray, first, count, counters, [&](const auto& candidate) {
            hit |= candidate.keep_nearest(best);
            return false;
        });
        if (hit) t_max = round_up(best.t);
        return hit;
    }

    /// The occlusion leaf test: whether any primitive of the leaf is hit in [t_min, t_max].
    template <bool kCount, bool kWide>
    static bool occluded_in_leaf(const Tree& bvh, const LeafRayOf<kWide>& ray, std::uint32_t first,
                                 std::uint32_t count, TraversalCounters& counters) {
        return for_each_hit<kCount>(bvh, ray, first, count, counters,
                                    [](const auto& candidate) { return candidate.occludes(); });
    }

    template <bool kCount, bool kAvx2>
    static bool intersect(const Tree& bvh, const Ray& ray, HitRecord& record, QueryScratch& scratch,
                          TraversalCounters& counters) {
        if (bvh.set_ == nullptr) return false;
        // The leaf ray is made at the first leaf: most camera rays reach none (they miss the
        // mesh's boxes), and for them the set's prepare and the block ray are pure cost.
        // Raw storage rather than std::optional: LeafRay is trivially destructible, so nothing
        // is left to check or destroy on the way out.
        using LeafRay = LeafRayOf<kAvx2>;
        static_assert(std::is_trivially_destructible_v<LeafRay>);
        alignas(LeafRay) unsigned char leaf_ray_storage[sizeof(LeafRay)];
        const LeafRay* leaf_ray = nullptr;
        HitRecord best;
        best.t = ray.t_max;
        bool found = false;
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
            if (leaf_ray == nullptr) [[unlikely]]
                leaf_ray = new (leaf_ray_storage) LeafRay(*bvh.set_, ray, scratch);
            found |= nearest_in_leaf<kCount>(bvh, *leaf_ray, first, count, best, t_max, counters);
            return false;
        };
        traverse<kCount, kAvx2>(bvh, ray, counters, leaf);
        if (found) record = best;
        return found;
    }

    template <bool kCount, bool kAvx2>
    static bool occluded(const Tree& bvh, const Ray& ray, QueryScratch& scratch,
                         TraversalCounters& counters) {
        if (bvh.set_ == nullptr) return false;
        // Made up front, unlike intersect's: shadow rays start on a surface and nearly all
        // reach a leaf, and the deferred form cost them 58 instructions a ray (callgrind). (An
        // invalid ray makes it for nothing: the set's prepare is plain arithmetic.)
        const LeafRayOf<kAvx2> leaf_ray(*bvh.set_, ray, scratch);
        bool occluded = false;
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float&) {
            return occluded = occluded_in_leaf<kCount>(bvh, leaf_ray, first, count, counters);
        };
        traverse<kCount, kAvx2, false>(bvh, ray, counters, leaf);
        return occluded;
    }

    /// Every hit in the interval, the leaves' and nodes' work counted when kCount (a mesh's
    /// spans as a CSG operand are this walk).
    template <bool kCount, bool kAvx2>
    static void all_hits(const Tree& bvh, const Ray& ray, std::vector<HitRecord>& hits,
                         QueryScratch& scratch, TraversalCounters& counters) {
        if (bvh.set_ == nullptr) return;
        const LeafRayOf<kAvx2> leaf_ray(*bvh.set_, ray, scratch);
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float&) {
            return for_each_hit<kCount>(bvh, leaf_ray, first, count, counters,
                                        [&](const auto& candidate) {
                                            HitRecord record;
                                            record.t = ray.t_max;
                                            if (candidate.keep_nearest(record))
                                                hits.push_back(record);
                                            return false;
                                        });
        };
        traverse<kCount, kAvx2, false>(bvh, ray, counters, leaf);
    }

    /// The packet queries (bvh_packet.cpp): a member, so that they share the traversal's
    /// friendship with Bvh and call its walk and leaf tests as their own.
    struct Packets;
};

}  // namespace csgrt::detail
