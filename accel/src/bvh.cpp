#include "csgrt/accel/bvh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <new>
#include <span>
#include <type_traits>

#include "accelerator_base.h"
#include "bvh_leaf.h"
#include "bvh_ray.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"

namespace csgrt {

namespace {

using detail::kBlockLanes;
using detail::kFloatInfinity;
using detail::round_down;
using detail::round_up;

/// A primitive's box padded by kPrimitivePadding of its size and magnitude and rounded
/// outward to float.
void pad_box(const Aabb& box, detail::BuildPrimitive& primitive) {
    if (box.is_empty()) {
        for (int axis = 0; axis < 3; ++axis) {
            primitive.lower[axis] = kFloatInfinity;
            primitive.upper[axis] = -kFloatInfinity;
        }
        return;
    }
    const double magnitude =
        std::max(box.lower.cwiseAbs().maxCoeff(), box.upper.cwiseAbs().maxCoeff());
    const double padding =
        Bvh<TriangleSet<float>>::kPrimitivePadding * (magnitude + box.diagonal().maxCoeff());
    for (int axis = 0; axis < 3; ++axis) {
        primitive.lower[axis] = round_down(box.lower[axis] - padding);
        primitive.upper[axis] = round_up(box.upper[axis] + padding);
    }
}

/// pad_box for a triangle of float corners, in float: twice the padding, computed with
/// rounding to nearest, still leaves each bound at least kPrimitivePadding (magnitude + size)
/// beyond the exact one, because the rounding errors are at most a few 2^-24 of the magnitude,
/// far below the padding's 2^-18 of it; the padding is at least the smallest normal float, so
/// tiny coordinates are padded too. Corners that are not all finite take the double path.
void pad_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                  detail::BuildPrimitive& primitive) {
    const Eigen::Vector3f lower = a.cwiseMin(b).cwiseMin(c);
    const Eigen::Vector3f upper = a.cwiseMax(b).cwiseMax(c);
    const float magnitude = std::max(lower.cwiseAbs().maxCoeff(), upper.cwiseAbs().maxCoeff());
    if (!(magnitude <= std::numeric_limits<float>::max())) {
        Aabb box;
        for (const Eigen::Vector3f* corner : {&a, &b, &c}) box.extend(corner->cast<double>());
        pad_box(box, primitive);
        return;
    }
    constexpr auto kPadding = static_cast<float>(2.0 * Bvh<TriangleSet<float>>::kPrimitivePadding);
    const float padding = std::max(kPadding * (magnitude + (upper - lower).maxCoeff()),
                                   std::numeric_limits<float>::min());
    for (int axis = 0; axis < 3; ++axis) {
        primitive.lower[axis] = lower[axis] - padding;
        primitive.upper[axis] = upper[axis] + padding;
    }
}

}  // namespace

namespace detail {

/// Everything the queries do, for each layout and instruction set; a friend of Bvh.
template <class Set>
struct BvhTraversal {
    using Tree = Bvh<Set>;
    static constexpr bool kBlockSet = std::is_same_v<Set, TriangleSet<float>>;

    struct BinaryEntry {
        std::uint32_t node;
        float t_enter;
    };
    struct WideEntry {
        std::uint32_t first;
        std::uint32_t count;
        float t_enter;
    };

    /// Visits every leaf the ray may hit within [t_min, t_max], nearest entry first. `leaf`
    /// is called as leaf(first, count, t_max) with the leaf's reference (see Bvh::
    /// binary_nodes) and the float upper bound of the interval, which it may lower; it
    /// returns true to stop. kAvx2: the 8-wide tree with the AVX2 node test (run_avx2 only).
    template <bool kCount, bool kAvx2, class Leaf>
    static void traverse(const Tree& bvh, const Ray& ray, const BoxRay& box_ray,
                         TraversalCounters& counters, Leaf& leaf) {
#if CSGRT_BVH_AVX2
        if constexpr (kAvx2) {
            if (box_ray.signed_interval) {
                return traverse_wide<kCount, true, Avx2NodeTest>(bvh, bvh.nodes_8_, box_ray,
                                                                 ray.t_max, counters, leaf);
            }
            return traverse_wide<kCount, false, Avx2NodeTest>(bvh, bvh.nodes_8_, box_ray, ray.t_max,
                                                              counters, leaf);
        }
#endif
        if (bvh.config_.width == 8) {
            if (box_ray.signed_interval) {
                return traverse_wide<kCount, true, SseNodeTest<8>>(bvh, bvh.nodes_8_, box_ray,
                                                                   ray.t_max, counters, leaf);
            }
            return traverse_wide<kCount, false, SseNodeTest<8>>(bvh, bvh.nodes_8_, box_ray,
                                                                ray.t_max, counters, leaf);
        }
        if (bvh.config_.width == 4) {
            if (box_ray.signed_interval) {
                return traverse_wide<kCount, true, SseNodeTest<4>>(bvh, bvh.nodes_4_, box_ray,
                                                                   ray.t_max, counters, leaf);
            }
            return traverse_wide<kCount, false, SseNodeTest<4>>(bvh, bvh.nodes_4_, box_ray,
                                                                ray.t_max, counters, leaf);
        }
        if (box_ray.signed_interval) {
            return traverse_binary<kCount, true>(bvh, box_ray, ray.t_max, counters, leaf);
        }
        traverse_binary<kCount, false>(bvh, box_ray, ray.t_max, counters, leaf);
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
            all_hits<kAvx2>(bvh, ray, answer, scratch);
            return answer.size() > before;
        }
    }

#if CSGRT_BVH_AVX2
    /// The whole query compiled for AVX2: `flatten` inlines everything it calls (the ray's
    /// set-up, the traversal, the leaf visitor, the triangle test), so all of it is AVX2 code,
    /// here and nowhere else, with no call between the set-up and the traversal.
    template <QueryKind kKind, bool kCount>
    [[gnu::target("avx2"), gnu::flatten]] static bool run_avx2(const Tree& bvh, const Ray& ray,
                                                               QueryAnswer<kKind>& answer,
                                                               QueryScratch& scratch,
                                                               TraversalCounters& counters) {
        return run<kKind, kCount, true>(bvh, ray, answer, scratch, counters);
    }
#endif

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
        } else if (!bvh.blocks_.empty()) {
            fetch(&bvh.blocks_[first], sizeof(BvhTriangleBlock) + 32);
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

    template <bool kCount, bool kSigned, class NodeTest, int kWidth, class Leaf>
    static void traverse_wide(const Tree& bvh, const WideBvhNodes<kWidth>& nodes,
                              const BoxRay& box_ray, double ray_t_max, TraversalCounters& counters,
                              Leaf& leaf) {
        if (nodes.empty()) return;
        const NodeTest test(box_ray);
        walk_wide<kCount, kSigned>(bvh, nodes, test, round_up(ray_t_max), counters, leaf);
    }

    /// traverse_wide with its node test made: `test.hit<kSigned>(node, t_max, t_enter)` gives
    /// the mask of the children to enter (a single ray's, or a packet's conservative one).
    template <bool kCount, bool kSigned, class NodeTest, int kWidth, class Leaf>
    static void walk_wide(const Tree& bvh, const WideBvhNodes<kWidth>& nodes, const NodeTest& test,
                          float t_max, TraversalCounters& counters, Leaf& leaf) {
        using Node = WideBvhNode<kWidth>;

        // Each level pushes at most kWidth - 1 children.
        WideEntry stack[(kWidth - 1) * kMaxDepth + 1];
        WideEntry* top = stack;
        std::uint32_t first = 0, count = Node::kInterior;
        alignas(32) float t_enter[kWidth];
        for (;;) {
            // Descend through interior nodes, nearest child first, until a leaf or a dead end.
            while (count == Node::kInterior) {
                const Node& node = nodes[first];
                if constexpr (kCount) {
                    ++counters.nodes_visited;
                    counters.boxes_tested += kWidth;
                }
                unsigned mask = test.template hit<kSigned>(node, t_max, t_enter);
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
                // Three or more children: push them all, then order the pushed entries so that
                // the nearest is on top, and take it. Those left waiting are fetched while the
                // nearest one is traversed.
                WideEntry* pushed = top;
                *top++ = WideEntry{first, count, t_enter[nearest]};
                prefetch(bvh, nodes, first, count);
                do {
                    const int slot = std::countr_zero(mask);
                    mask &= mask - 1;
                    *top++ = WideEntry{node.first[slot], node.count[slot], t_enter[slot]};
                    prefetch(bvh, nodes, node.first[slot], node.count[slot]);
                } while (mask != 0);
                for (WideEntry* i = pushed + 1; i != top; ++i) {
                    const WideEntry entry = *i;
                    WideEntry* j = i;
                    for (; j != pushed && (j - 1)->t_enter < entry.t_enter; --j) *j = *(j - 1);
                    *j = entry;
                }
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
            if (!bvh.blocks_.empty()) {
                // The candidate lanes of one block, finished by BlockHits (or by the set's
                // test where an edge function is zero) and handed to visit.
                auto visit_block = [&](const BvhTriangleBlock& block, const ShearedBlock& sheared,
                                       unsigned candidates, unsigned zeros) {
                    const BlockHits hits(sheared, ray.prepared.shear_z);
                    do {
                        const int lane = std::countr_zero(candidates);
                        candidates &= candidates - 1;
                        double t = hits.t[lane], b1 = hits.b1[lane], b2 = hits.b2[lane];
                        if ((zeros >> lane & 1u) != 0 &&
                            !TriangleSet<float>::hit_sheared(sheared.lane(lane),
                                                             ray.prepared.shear_z, t, b1, b2)) {
                            continue;
                        }
                        if (visit(BlockCandidate{block.primitive[lane], t, b1, b2, ray.prepared}))
                            return true;
                    } while (candidates != 0);
                    return false;
                };
                const BvhTriangleBlock* block = bvh.blocks_.data() + first;
                std::uint32_t left = count;
                if constexpr (LeafRayOf<kWide>::kPairs) {
                    for (; left > kBlockLanes; block += 2) {
                        const std::uint32_t lanes = std::min(left, 2 * kBlockLanes);
                        left -= lanes;
                        if constexpr (kCount) counters.primitives_tested += lanes;
                        ShearedBlock sheared[2];
                        unsigned zeros;
                        const unsigned candidates =
                            ray.wide.candidates(block[0], block[1], sheared, zeros) &
                            ((1u << lanes) - 1u);
                        if ((candidates & 0xfu) != 0 &&
                            visit_block(block[0], sheared[0], candidates & 0xfu, zeros & 0xfu)) {
                            return true;
                        }
                        if ((candidates >> 4) != 0 &&
                            visit_block(block[1], sheared[1], candidates >> 4, zeros >> 4)) {
                            return true;
                        }
                    }
                }
                for (; left != 0; ++block) {
                    const std::uint32_t lanes = std::min(left, kBlockLanes);
                    left -= lanes;
                    if constexpr (kCount) counters.primitives_tested += lanes;
                    ShearedBlock sheared;
                    unsigned zeros;
                    const unsigned candidates =
                        ray.block.candidates(*block, sheared, zeros) & ((1u << lanes) - 1u);
                    if (candidates != 0 && visit_block(*block, sheared, candidates, zeros))
                        return true;
                }
                return false;
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
        const BoxRay box_ray(ray);
        if (!box_ray.valid) return false;
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
        traverse<kCount, kAvx2>(bvh, ray, box_ray, counters, leaf);
        if (found) record = best;
        return found;
    }

    template <bool kCount, bool kAvx2>
    static bool occluded(const Tree& bvh, const Ray& ray, QueryScratch& scratch,
                         TraversalCounters& counters) {
        if (bvh.set_ == nullptr) return false;
        const BoxRay box_ray(ray);
        if (!box_ray.valid) return false;
        // Made up front, unlike intersect's: shadow rays start on a surface and nearly all
        // reach a leaf, and the deferred form cost them 58 instructions a ray (callgrind).
        const LeafRayOf<kAvx2> leaf_ray(*bvh.set_, ray, scratch);
        bool occluded = false;
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float&) {
            return occluded = occluded_in_leaf<kCount>(bvh, leaf_ray, first, count, counters);
        };
        traverse<kCount, kAvx2>(bvh, ray, box_ray, counters, leaf);
        return occluded;
    }

    template <bool kAvx2>
    static void all_hits(const Tree& bvh, const Ray& ray, std::vector<HitRecord>& hits,
                         QueryScratch& scratch) {
        if (bvh.set_ == nullptr) return;
        const BoxRay box_ray(ray);
        if (!box_ray.valid) return;
        const LeafRayOf<kAvx2> leaf_ray(*bvh.set_, ray, scratch);
        TraversalCounters unused;
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float&) {
            return for_each_hit<false>(bvh, leaf_ray, first, count, unused,
                                       [&](const auto& candidate) {
                                           HitRecord record;
                                           record.t = ray.t_max;
                                           if (candidate.keep_nearest(record))
                                               hits.push_back(record);
                                           return false;
                                       });
        };
        traverse<false, kAvx2>(bvh, ray, box_ray, unused, leaf);
    }

#if CSGRT_BVH_AVX2
    template <class NodeTest>
    static constexpr bool kAvx2Test = std::is_same_v<NodeTest, Avx2NodeTest>;
#else
    template <class NodeTest>
    static constexpr bool kAvx2Test = false;
#endif

    /// The rays of a packet: each one's box ray and float upper bound, and, made when first
    /// needed, its node test (the ray-by-ray walk only) and its leaf ray (at its first leaf:
    /// most camera rays reach none).
    template <class NodeTest>
    struct PacketLanes {
        using LeafRayType = LeafRayOf<kAvx2Test<NodeTest>>;
        struct Lane {
            BoxRay box;
            float t_max;
        };
        static_assert(std::is_trivially_destructible_v<Lane> &&
                      std::is_trivially_destructible_v<NodeTest> &&
                      std::is_trivially_destructible_v<LeafRayType>);
        alignas(Lane) unsigned char lane_storage[sizeof(Lane) * Tree::kPacketRays];
        alignas(NodeTest) unsigned char test_storage[sizeof(NodeTest) * Tree::kPacketRays];
        alignas(LeafRayType) unsigned char leaf_storage[sizeof(LeafRayType) * Tree::kPacketRays];
        std::uint32_t leaf_made = 0;

        Lane& operator[](int r) { return reinterpret_cast<Lane*>(lane_storage)[r]; }
        const Lane& operator[](int r) const {
            return reinterpret_cast<const Lane*>(lane_storage)[r];
        }
        void make(int r, const Ray& ray) {
            new (&(*this)[r]) Lane{BoxRay(ray), round_up(ray.t_max)};
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
                                                   lanes[r].t_max, unused);
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
                                                  scratch);
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
                    const auto& lane = lanes[r];
                    const NodeTest& test = lanes.test(r);
                    alignas(32) float t_enter[kWidth];
                    const unsigned mask = lane.box.signed_interval
                                              ? test.template hit<true>(node, lane.t_max, t_enter)
                                              : test.template hit<false>(node, lane.t_max, t_enter);
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
                for (PacketEntry* i = pushed + 1; i != top; ++i) {
                    const PacketEntry entry = *i;
                    PacketEntry* j = i;
                    for (; j != pushed && (j - 1)->t_enter < entry.t_enter; --j) *j = *(j - 1);
                    *j = entry;
                }
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
                    if (top->t_enter > lanes[r].t_max) active &= ~(1u << r);
                }
            } while (active == 0);
            first = top->first;
            count = top->count;
        }
    }

#if CSGRT_BVH_AVX2
    /// traverse_packet with the AVX2 node test, everything inlined and compiled for AVX2.
    template <bool kAny>
    [[gnu::target("avx2"), gnu::flatten]] static void traverse_packet_avx2(
        const Tree& bvh, std::span<const Ray> rays, HitRecord* best, bool* found,
        QueryScratch& scratch) {
        traverse_packet<kAny, Avx2NodeTest>(bvh, bvh.nodes_8_, rays, best, found, scratch);
    }
#endif

#if CSGRT_BVH_AVX2
    /// The nearest hits (or occlusion) of a packet whose rays PacketIntervalTest accepts: the
    /// tree is walked once with the packet's conservative node test, as one ray would walk it,
    /// and every leaf it reaches is tested for each open ray with that ray's own leaf test and
    /// t_max. The upper bound of the walk is the largest t_max of the open rays.
    template <bool kAny>
    [[gnu::target("avx2")]] static void walk_interval_packet(
        const Tree& bvh, std::span<const Ray> rays, PacketLanes<Avx2NodeTest>& lanes,
        std::uint32_t open, const PacketIntervalTest& test, HitRecord* best, bool* found,
        QueryScratch& scratch) {
        TraversalCounters unused;
        auto largest_t_max = [&] {
            float t_max = -kFloatInfinity;
            for (std::uint32_t m = open; m != 0; m &= m - 1)
                t_max = std::max(t_max, lanes[std::countr_zero(m)].t_max);
            return t_max;
        };
        if constexpr (kBlockSet) {
            if (!bvh.blocks_.empty()) {
                // Ray-parallel leaves, when the rays share the triangle test's axes.
                typename Set::PreparedRay prepared[Tree::kPacketRays];
                for (std::uint32_t m = open; m != 0; m &= m - 1) {
                    const int r = std::countr_zero(m);
                    prepared[r] = bvh.set_->prepare(rays[r], scratch);
                }
                PacketTriangleRays triangle_rays;
                if (triangle_rays.accepts(prepared, open)) {
                    auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
                        const BvhTriangleBlock* block = bvh.blocks_.data() + first;
                        for (std::uint32_t left = count; left != 0; ++block) {
                            const std::uint32_t block_lanes = std::min(left, kBlockLanes);
                            left -= block_lanes;
                            for (std::uint32_t lane = 0; lane < block_lanes; ++lane) {
                                alignas(32) float sheared[9][8];
                                unsigned candidates = triangle_rays.candidates(
                                    *block, static_cast<int>(lane), open, sheared);
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
                                    if (!TriangleSet<float>::hit_sheared(
                                            triangle, prepared[r].shear_z, t, b1, b2)) {
                                        continue;
                                    }
                                    if constexpr (kAny) {
                                        if (t >= prepared[r].t_min && t <= prepared[r].t_max) {
                                            found[r] = true;
                                            open &= ~(1u << r);
                                        }
                                    } else if (Set::keep_nearest(block->primitive[lane], t, b1, b2,
                                                                 prepared[r], best[r])) {
                                        found[r] = true;
                                        lanes[r].t_max = round_up(best[r].t);
                                    }
                                }
                                if (open == 0) return true;
                            }
                        }
                        t_max = largest_t_max();
                        return false;
                    };
                    walk_wide<false, false>(bvh, bvh.nodes_8_, test, largest_t_max(), unused, leaf);
                    return;
                }
            }
        }
        auto leaf = [&](std::uint32_t first, std::uint32_t count, float& t_max) {
            leaf_for_rays<kAny>(bvh, rays, lanes, open, first, count, best, found, open, scratch);
            t_max = largest_t_max();
            return open == 0;
        };
        walk_wide<false, false>(bvh, bvh.nodes_8_, test, largest_t_max(), unused, leaf);
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
void Bvh<Set>::build(const Set& set, const BvhConfig& config) {
    require(config.bins >= 2 && config.bins <= 256, "Bvh", "bins", "in [2, 256]", config.bins);
    require(config.max_leaf_size >= 1, "Bvh", "max_leaf_size", ">= 1", config.max_leaf_size);
    require_positive(config.traversal_cost, "Bvh", "traversal_cost");
    require_positive(config.intersection_cost, "Bvh", "intersection_cost");
    require(config.width == 2 || config.width == 4 || config.width == 8, "Bvh", "width",
            "2, 4 or 8", config.width);
    // Node indices (up to twice the primitive count) and leaf counts are 32-bit.
    require(set.size() < (std::size_t{1} << 31), "Bvh", "primitive count", "< 2^31", set.size());
    const auto start = std::chrono::steady_clock::now();
    set_ = &set;
    config_ = config;
    constexpr bool kBlockSet = detail::BvhTraversal<Set>::kBlockSet;
    const bool blocks = kBlockSet && config.triangle_blocks;
    use_avx2_ = false;
#if CSGRT_BVH_AVX2
    use_avx2_ = config.width == 8 && config.avx2 && __builtin_cpu_supports("avx2");
#endif

    // Left uninitialised here (AlignedAllocator default-initialises) and written in parallel
    // below, so that the tasks also take the page faults of the 32 bytes a primitive.
    std::vector<detail::BuildPrimitive, AlignedAllocator<detail::BuildPrimitive>> primitives(
        set.size());
    auto prepare_range = [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            detail::BuildPrimitive& primitive = primitives[i];
            if constexpr (kBlockSet) {
                pad_triangle(set.corner(i, 0), set.corner(i, 1), set.corner(i, 2), primitive);
            } else {
                pad_box(set.bounds(i), primitive);
            }
            primitive.index = static_cast<std::uint32_t>(i);
            primitive.unused = 0.0f;
        }
    };
    const tbb::blocked_range<std::size_t> all(0, set.size(), 4096);
    if (config.parallel) {
        tbb::parallel_for(all, prepare_range);
    } else {
        prepare_range(all);
    }

    detail::BinaryBvh tree =
        detail::build_binary_bvh(primitives, config, blocks ? int(kBlockLanes) : 1);
    primitives = {};

    // Leaves name their contents: blocks of four triangles copied in leaf order, or entries
    // of the index array (a one-primitive leaf names its primitive itself). Leaves cover the
    // index array in order, so blocks are handed out in that order too.
    indices_.clear();
    blocks_.clear();
    if constexpr (kBlockSet) {
        if (blocks) fill_blocks(set, tree, config.parallel);
    }
    if (!blocks) {
        for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
            BvhNode& node = tree.nodes[i];
            if (i != 1 && node.count == 1) node.offset = tree.indices[node.offset];
        }
        indices_ = std::move(tree.indices);
    }

    nodes_4_.clear();
    nodes_8_.clear();
    binary_nodes_.clear();
    if (config.width == 4) {
        nodes_4_ = detail::collapse_to_wide<4>(tree, config.parallel);
    } else if (config.width == 8) {
        nodes_8_ = detail::collapse_to_wide<8>(tree, config.parallel);
    } else {
        binary_nodes_ = std::move(tree.nodes);
        binary_nodes_.shrink_to_fit();
    }

    stats_ = AcceleratorStats{};
    stats_.name = "bvh";
    // The wide nodes are counted by size: collapse_to_wide reserves more address space than it
    // uses, and the pages it never writes are never mapped.
    stats_.bytes = binary_nodes_.capacity() * sizeof(BvhNode) + nodes_4_.size() * sizeof(Bvh4Node) +
                   nodes_8_.size() * sizeof(Bvh8Node) +
                   indices_.capacity() * sizeof(std::uint32_t) +
                   blocks_.capacity() * sizeof(BvhTriangleBlock);
    stats_.nodes = nodes_4_.size() + nodes_8_.size() + binary_nodes_.size();
    stats_.primitives = stats_.references = set.size();
    char details[240];
    std::snprintf(details, sizeof details,
                  "width %d, depth %d, %zu leaves (%.2f primitives each), %zu blocks, SAH cost "
                  "%.2f, %d bins, %.1f bytes per primitive%s",
                  config.width, tree.depth, tree.leaves,
                  tree.leaves ? double(set.size()) / double(tree.leaves) : 0.0, blocks_.size(),
                  tree.sah_cost, config.bins,
                  set.size() ? double(stats_.bytes) / double(set.size()) : 0.0,
                  use_avx2_ ? ", AVX2" : "");
    stats_.details = details;
    stats_.build_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
void Bvh<Set>::fill_blocks(const Set& set, detail::BinaryBvh& tree, bool parallel) {
    if (tree.nodes.empty()) return;
    // The leaves in index order: depth first, left child first.
    std::vector<std::uint32_t> leaves, pending{0};
    leaves.reserve(tree.leaves);
    while (!pending.empty()) {
        const std::uint32_t index = pending.back();
        pending.pop_back();
        const BvhNode& node = tree.nodes[index];
        if (node.is_leaf()) {
            leaves.push_back(index);
        } else {
            pending.push_back(node.offset + 1);
            pending.push_back(node.offset);
        }
    }
    std::vector<std::uint32_t> first_block(leaves.size() + 1, 0);
    for (std::size_t k = 0; k < leaves.size(); ++k) {
        first_block[k + 1] =
            first_block[k] + (tree.nodes[leaves[k]].count + kBlockLanes - 1) / kBlockLanes;
    }
    // Every lane of every block is written below: lanes past a leaf's count get zeros and
    // kNoIndex. The storage is left uninitialised until then.
    blocks_.resize(first_block.back());
    auto fill = [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            BvhNode& node = tree.nodes[leaves[k]];
            for (std::uint32_t slot = 0;
                 slot != (first_block[k + 1] - first_block[k]) * kBlockLanes; ++slot) {
                BvhTriangleBlock& block = blocks_[first_block[k] + slot / kBlockLanes];
                const std::uint32_t lane = slot % kBlockLanes;
                const bool used = slot < node.count;
                const std::uint32_t primitive = used ? tree.indices[node.offset + slot] : kNoIndex;
                block.primitive[lane] = primitive;
                if constexpr (detail::BvhTraversal<Set>::kBlockSet) {
                    for (int corner = 0; corner < 3; ++corner) {
                        for (int axis = 0; axis < 3; ++axis) {
                            block.corners[corner][axis][lane] =
                                used ? set.corner(primitive, corner)[axis] : 0.0f;
                        }
                    }
                }
            }
            node.offset = first_block[k];
        }
    };
    const tbb::blocked_range<std::size_t> all(0, leaves.size(), 1024);
    if (parallel) {
        tbb::parallel_for(all, fill);
    } else {
        fill(all);
    }
    tree.indices = {};
}

template <class Set>
template <QueryKind kKind, bool kCounted>
bool Bvh<Set>::query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
                     TraversalCounters& counters) const {
    using Traversal = detail::BvhTraversal<Set>;
#if CSGRT_BVH_AVX2
    if (use_avx2_)
        return Traversal::template run_avx2<kKind, kCounted>(*this, ray, answer, scratch, counters);
#endif
    return Traversal::template run<kKind, kCounted, false>(*this, ray, answer, scratch, counters);
}

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
        HitRecord best[kPacketRays];
        bool found[kPacketRays];
        for (std::size_t begin = 0; begin < rays.size(); begin += kPacketRays) {
            const std::size_t n = std::min(kPacketRays, rays.size() - begin);
            detail::BvhTraversal<Set>::template packet<kAny>(*this, rays.subspan(begin, n), best,
                                                             found, scratch);
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

template class Bvh<TriangleSet<float>>;
template class Bvh<TriangleSet<double>>;
template class Bvh<ShapeSet>;
template class AcceleratorBase<Bvh<TriangleSet<float>>, TriangleSet<float>>;
template class AcceleratorBase<Bvh<TriangleSet<double>>, TriangleSet<double>>;
template class AcceleratorBase<Bvh<ShapeSet>, ShapeSet>;

}  // namespace csgrt
