#include "csgrt/accel/bvh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace csgrt {

namespace {

constexpr float kFloatInfinity = std::numeric_limits<float>::infinity();
constexpr double kFloatMax = std::numeric_limits<float>::max();
/// Beyond this a coordinate or reciprocal direction component is not trusted to the float
/// slab test (products could overflow or underflow to denormals).
constexpr double kLargestBoxRayValue = 0x1p100;

/// The largest float <= x (x not NaN).
float round_down(double x) {
    if (x > kFloatMax) return static_cast<float>(kFloatMax);
    if (x < -kFloatMax) return -kFloatInfinity;
    float f = static_cast<float>(x);
    if (double(f) > x) f = std::nextafter(f, -kFloatInfinity);
    return f;
}

/// The smallest float >= x (x not NaN).
float round_up(double x) {
    if (x > kFloatMax) return kFloatInfinity;
    if (x < -kFloatMax) return -static_cast<float>(kFloatMax);
    float f = static_cast<float>(x);
    if (double(f) < x) f = std::nextafter(f, kFloatInfinity);
    return f;
}

constexpr float kSlack = Bvh<TriangleSet<float>>::kSlabSlack;

/// The ray as the float slab tests see it. The origin is rounded to nearest, as the float
/// triangle test rounds it, so both tests measure t from the same point.
///
/// The slack widens [t_enter, t_exit] by kSlabSlack of its magnitude at both ends. When
/// t_min >= 0 only non-negative distances can matter (a negative t_exit means a miss either
/// way, and rounding never flips a sign), so it is folded into the reciprocals: near planes
/// use (1 - slack) / d, far planes (1 + slack) / d. Otherwise (`signed_interval`) the
/// traversal widens each interval by its magnitude.
}  // namespace

namespace detail {
struct BoxRay {
    float origin[3];
    float inverse_near[3];
    float inverse_far[3];
    /// Whether the direction's sign bit is set (-0 included): the box's upper face is then
    /// the near one, and the products below never form 0 * inf except in a face's plane.
    bool negative[3];
    bool signed_interval;
    float t_min;

    explicit BoxRay(const Ray& ray) {
        bool representable = true;
        for (int axis = 0; axis < 3; ++axis) {
            const double d = ray.direction[axis];
            representable &= std::abs(ray.origin[axis]) <= kLargestBoxRayValue &&
                             (d == 0.0 || (std::abs(d) <= kLargestBoxRayValue &&
                                           std::abs(d) >= 1.0 / kLargestBoxRayValue));
            negative[axis] = std::signbit(d);
        }
        t_min = round_down(ray.t_min);
        signed_interval = !(t_min >= 0.0f);
        if (!representable) {
            // Every slab distance becomes NaN, which the tests ignore: every box is entered.
            for (int axis = 0; axis < 3; ++axis) {
                origin[axis] = 0.0f;
                inverse_near[axis] = inverse_far[axis] = std::numeric_limits<float>::quiet_NaN();
            }
            t_min = -kFloatInfinity;
            signed_interval = true;
            return;
        }
        const float near_scale = signed_interval ? 1.0f : 1.0f - kSlack;
        const float far_scale = signed_interval ? 1.0f : 1.0f + kSlack;
        for (int axis = 0; axis < 3; ++axis) {
            origin[axis] = static_cast<float>(ray.origin[axis]);
            // +-0 gives +-inf, whose products with plane distances are +-inf or NaN.
            const float inverse = 1.0f / static_cast<float>(ray.direction[axis]);
            inverse_near[axis] = inverse * near_scale;
            inverse_far[axis] = inverse * far_scale;
        }
    }
};

}  // namespace detail

namespace {
using detail::BoxRay;

/// Conservative slab test of one binary node's box: [t_enter, t_exit] clipped to
/// [t_min, t_max] and widened by the slack; true when it is not empty. An empty box gives an
/// empty interval (or NaN, which compares false).
template <bool kSigned>
bool hit_box(const BvhNode& node, const BoxRay& ray, float t_max, float& t_enter) {
    float t0 = ray.t_min, t1 = t_max;
    for (int axis = 0; axis < 3; ++axis) {
        const float near_plane = ray.negative[axis] ? node.upper[axis] : node.lower[axis];
        const float far_plane = ray.negative[axis] ? node.lower[axis] : node.upper[axis];
        const float t_near = (near_plane - ray.origin[axis]) * ray.inverse_near[axis];
        const float t_far = (far_plane - ray.origin[axis]) * ray.inverse_far[axis];
        // NaN (0 * inf: a ray parallel to the slab, in a face's plane) leaves t0, t1 as they
        // are: the ray is inside that slab for every t.
        t0 = t_near > t0 ? t_near : t0;
        t1 = t_far < t1 ? t_far : t1;
    }
    if constexpr (kSigned) {
        t0 -= std::abs(t0) * kSlack;
        t1 += std::abs(t1) * kSlack;
    }
    t_enter = t0;
    return t0 <= t1;
}

/// The four boxes of a 4-wide node at once, with the arithmetic of hit_box lane by lane.
struct WideBoxRay {
    /// Rows of WideBvhNode::bounds holding each axis' near and far planes.
    std::size_t near_row[3], far_row[3];
#if defined(__SSE2__)
    __m128 origin[3], inverse_near[3], inverse_far[3], t_min;

    explicit WideBoxRay(const BoxRay& ray) {
        for (int axis = 0; axis < 3; ++axis) {
            origin[axis] = _mm_set1_ps(ray.origin[axis]);
            inverse_near[axis] = _mm_set1_ps(ray.inverse_near[axis]);
            inverse_far[axis] = _mm_set1_ps(ray.inverse_far[axis]);
            near_row[axis] = 2 * axis + (ray.negative[axis] ? 1 : 0);
            far_row[axis] = 2 * axis + (ray.negative[axis] ? 0 : 1);
        }
        t_min = _mm_set1_ps(ray.t_min);
    }

    /// Bit i of the result says child i is entered, at t_enter[i].
    template <bool kSigned, int kWidth>
    int hit(const WideBvhNode<kWidth>& node, float t_max, float* t_enter) const {
        int mask = 0;
        const __m128 t_max4 = _mm_set1_ps(t_max);
        for (int group = 0; group < kWidth; group += 4) {
            const float* bounds = node.bounds[0] + group;
            __m128 t0 = t_min, t1 = t_max4;
            for (int axis = 0; axis < 3; ++axis) {
                const __m128 t_near = _mm_mul_ps(
                    _mm_sub_ps(_mm_load_ps(bounds + kWidth * near_row[axis]), origin[axis]),
                    inverse_near[axis]);
                const __m128 t_far = _mm_mul_ps(
                    _mm_sub_ps(_mm_load_ps(bounds + kWidth * far_row[axis]), origin[axis]),
                    inverse_far[axis]);
                // maxps and minps return their second operand when either is NaN: NaN slabs
                // are ignored, as in hit_box.
                t0 = _mm_max_ps(t_near, t0);
                t1 = _mm_min_ps(t_far, t1);
            }
            if constexpr (kSigned) {
                const __m128 sign = _mm_set1_ps(-0.0f), slack = _mm_set1_ps(kSlack);
                t0 = _mm_sub_ps(t0, _mm_mul_ps(_mm_andnot_ps(sign, t0), slack));
                t1 = _mm_add_ps(t1, _mm_mul_ps(_mm_andnot_ps(sign, t1), slack));
            }
            _mm_store_ps(t_enter + group, t0);
            mask |= _mm_movemask_ps(_mm_cmple_ps(t0, t1)) << group;
        }
        return mask;
    }
#else
    float origin[3], inverse_near[3], inverse_far[3], t_min;

    explicit WideBoxRay(const BoxRay& ray) {
        for (int axis = 0; axis < 3; ++axis) {
            origin[axis] = ray.origin[axis];
            inverse_near[axis] = ray.inverse_near[axis];
            inverse_far[axis] = ray.inverse_far[axis];
            near_row[axis] = 2 * axis + (ray.negative[axis] ? 1 : 0);
            far_row[axis] = 2 * axis + (ray.negative[axis] ? 0 : 1);
        }
        t_min = ray.t_min;
    }

    template <bool kSigned, int kWidth>
    int hit(const WideBvhNode<kWidth>& node, float t_max, float* t_enter) const {
        int mask = 0;
        for (int lane = 0; lane < kWidth; ++lane) {
            float t0 = t_min, t1 = t_max;
            for (int axis = 0; axis < 3; ++axis) {
                const float t_near =
                    (node.bounds[near_row[axis]][lane] - origin[axis]) * inverse_near[axis];
                const float t_far =
                    (node.bounds[far_row[axis]][lane] - origin[axis]) * inverse_far[axis];
                t0 = t_near > t0 ? t_near : t0;
                t1 = t_far < t1 ? t_far : t1;
            }
            if constexpr (kSigned) {
                t0 -= std::abs(t0) * kSlack;
                t1 += std::abs(t1) * kSlack;
            }
            t_enter[lane] = t0;
            mask |= (t0 <= t1) << lane;
        }
        return mask;
    }
#endif
};

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

/// Starts loading primitive i of the set, where the set lets us know where it is.
template <class Set>
void prefetch_primitive([[maybe_unused]] const Set& set, [[maybe_unused]] std::uint32_t i) {
#if defined(__SSE2__)
    if constexpr (requires { set.corner(std::size_t{0}, 0); }) {
        const char* corners = reinterpret_cast<const char*>(&set.corner(i, 0));
        _mm_prefetch(corners, _MM_HINT_T0);
        _mm_prefetch(corners + 3 * sizeof(set.corner(i, 0)) - 1, _MM_HINT_T0);
    }
#endif
}

/// Stack entries: a node (binary) or a child reference (wide), and its entry distance.
struct BinaryEntry {
    std::uint32_t node;
    float t_enter;
};
struct WideEntry {
    std::uint32_t first;
    std::uint32_t count;
    float t_enter;
};

}  // namespace

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

    std::vector<detail::BuildPrimitive> primitives(set.size());
    auto prepare_range = [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            detail::BuildPrimitive& primitive = primitives[i];
            pad_box(set.bounds(i), primitive);
            primitive.index = static_cast<std::uint32_t>(i);
        }
    };
    const tbb::blocked_range<std::size_t> all(0, set.size(), 4096);
    if (config.parallel) {
        tbb::parallel_for(all, prepare_range);
    } else {
        prepare_range(all);
    }

    detail::BinaryBvh tree = detail::build_binary_bvh(primitives, config);
    primitives = {};
    nodes_4_.clear();
    nodes_8_.clear();
    binary_nodes_.clear();
    if (config.width == 4) {
        nodes_4_ = detail::collapse_to_wide<4>(tree);
    } else if (config.width == 8) {
        nodes_8_ = detail::collapse_to_wide<8>(tree);
    } else {
        binary_nodes_ = std::move(tree.nodes);
    }
    indices_ = std::move(tree.indices);

    stats_ = AcceleratorStats{};
    stats_.name = "bvh";
    stats_.bytes = binary_nodes_.capacity() * sizeof(BvhNode) +
                   nodes_4_.capacity() * sizeof(Bvh4Node) + nodes_8_.capacity() * sizeof(Bvh8Node) +
                   indices_.capacity() * sizeof(std::uint32_t);
    stats_.nodes = nodes_4_.size() + nodes_8_.size() + binary_nodes_.size();
    stats_.primitives = stats_.references = set.size();
    char details[200];
    std::snprintf(details, sizeof details,
                  "width %d, depth %d, %zu leaves (%.2f primitives each), SAH cost %.2f, "
                  "%d bins, %.1f bytes per primitive",
                  config.width, tree.depth, tree.leaves,
                  tree.leaves ? double(set.size()) / double(tree.leaves) : 0.0, tree.sah_cost,
                  config.bins, set.size() ? double(stats_.bytes) / double(set.size()) : 0.0);
    stats_.details = details;
    stats_.build_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
template <bool kCount, class LeafVisitor>
void Bvh<Set>::traverse(const Ray& ray, TraversalCounters& counters, LeafVisitor&& leaf) const {
    const BoxRay box_ray(ray);
    if (config_.width == 4) {
        if (box_ray.signed_interval) {
            traverse_wide<kCount, true>(nodes_4_, box_ray, ray.t_max, counters, leaf);
        } else {
            traverse_wide<kCount, false>(nodes_4_, box_ray, ray.t_max, counters, leaf);
        }
    } else if (config_.width == 8) {
        if (box_ray.signed_interval) {
            traverse_wide<kCount, true>(nodes_8_, box_ray, ray.t_max, counters, leaf);
        } else {
            traverse_wide<kCount, false>(nodes_8_, box_ray, ray.t_max, counters, leaf);
        }
    } else {
        if (box_ray.signed_interval) {
            traverse_binary<kCount, true>(box_ray, ray.t_max, counters, leaf);
        } else {
            traverse_binary<kCount, false>(box_ray, ray.t_max, counters, leaf);
        }
    }
}

template <class Set>
template <bool kCount, bool kSigned, class LeafVisitor>
void Bvh<Set>::traverse_binary(const BoxRay& box_ray, double ray_t_max, TraversalCounters& counters,
                               LeafVisitor&& leaf) const {
    if (binary_nodes_.empty()) return;
    float t_max = round_up(ray_t_max);
    float t_enter;
    if constexpr (kCount) ++counters.boxes_tested;
    if (!hit_box<kSigned>(binary_nodes_[0], box_ray, t_max, t_enter)) return;

    // Each level pushes at most the far child, so the depth bounds the stack.
    BinaryEntry stack[detail::kMaxDepth + 1];
    int size = 0;
    std::uint32_t index = 0;
    for (;;) {
        const BvhNode& node = binary_nodes_[index];
        if constexpr (kCount) ++counters.nodes_visited;
        if (node.is_leaf()) {
            if (leaf(&indices_[node.offset], node.count, t_max)) return;
        } else {
            if constexpr (kCount) counters.boxes_tested += 2;
            float t_left, t_right;
            const bool left = hit_box<kSigned>(binary_nodes_[node.offset], box_ray, t_max, t_left);
            const bool right =
                hit_box<kSigned>(binary_nodes_[node.offset + 1], box_ray, t_max, t_right);
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

template <class Set>
template <bool kCount, bool kSigned, int kWidth, class LeafVisitor>
void Bvh<Set>::traverse_wide(const std::vector<WideBvhNode<kWidth>>& nodes, const BoxRay& box_ray,
                             double ray_t_max, TraversalCounters& counters,
                             LeafVisitor&& leaf) const {
    using Node = WideBvhNode<kWidth>;
    if (nodes.empty()) return;
    const WideBoxRay wide_ray(box_ray);
    float t_max = round_up(ray_t_max);

    // Each level pushes at most kWidth - 1 children.
    WideEntry stack[(kWidth - 1) * detail::kMaxDepth + 1];
    WideEntry* top = stack;
    std::uint32_t first = 0, count = Node::kInterior;
    alignas(16) float t_enter[kWidth];
    // Children that wait on the stack are fetched while the nearest one is traversed: a
    // node's two cache lines, a one-primitive leaf's primitive, a larger leaf's indices.
    auto prefetch = [&](std::uint32_t child_first, std::uint32_t child_count) {
#if defined(__SSE2__)
        if (child_count == Node::kInterior) {
            const char* address = reinterpret_cast<const char*>(&nodes[child_first]);
            for (std::size_t line = 0; line < sizeof(Node); line += 64)
                _mm_prefetch(address + line, _MM_HINT_T0);
        } else if (child_count == 1) {
            prefetch_primitive(*set_, child_first);
        } else {
            _mm_prefetch(reinterpret_cast<const char*>(&indices_[child_first]), _MM_HINT_T0);
        }
#endif
    };
    for (;;) {
        // Descend through interior nodes, nearest child first, until a leaf or a dead end.
        while (count == Node::kInterior) {
            const Node& node = nodes[first];
            if constexpr (kCount) {
                ++counters.nodes_visited;
                counters.boxes_tested += kWidth;
            }
            unsigned mask =
                static_cast<unsigned>(wide_ray.template hit<kSigned>(node, t_max, t_enter));
            if (mask == 0) break;
            const int nearest = std::countr_zero(mask);
            mask &= mask - 1;
            first = node.first[nearest];
            count = node.count[nearest];
            if (mask == 0) continue;
            // Two or more children: push them all, then order the pushed entries so that
            // the nearest is on top, and take it.
            WideEntry* pushed = top;
            *top++ = WideEntry{first, count, t_enter[nearest]};
            prefetch(first, count);
            do {
                const int slot = std::countr_zero(mask);
                mask &= mask - 1;
                *top++ = WideEntry{node.first[slot], node.count[slot], t_enter[slot]};
                prefetch(node.first[slot], node.count[slot]);
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
        if (count != Node::kInterior) {
            if constexpr (kCount) ++counters.nodes_visited;
            // A one-primitive leaf holds the primitive's index itself.
            const std::uint32_t* primitives = count == 1 ? &first : &indices_[first];
            if (leaf(primitives, count, t_max)) return;
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

template <class Set>
template <bool kCount>
bool Bvh<Set>::intersect_impl(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                              TraversalCounters& counters) const {
    if (set_ == nullptr || !is_valid(ray)) return false;
    const auto prepared = set_->prepare(ray, scratch);
    HitRecord best;
    best.t = ray.t_max;
    bool found = false;
    traverse<kCount>(ray, counters,
                     [&](const std::uint32_t* primitives, std::uint32_t count, float& t_max) {
                         if constexpr (kCount) counters.primitives_tested += count;
                         bool hit = false;
                         for (std::uint32_t i = 0; i != count; ++i)
                             hit |= set_->intersect(primitives[i], prepared, best);
                         if (hit) {
                             found = true;
                             t_max = round_up(best.t);
                         }
                         return false;
                     });
    if (found) record = best;
    return found;
}

template <class Set>
template <bool kCount>
bool Bvh<Set>::occluded_impl(const Ray& ray, QueryScratch& scratch,
                             TraversalCounters& counters) const {
    if (set_ == nullptr || !is_valid(ray)) return false;
    const auto prepared = set_->prepare(ray, scratch);
    bool occluded = false;
    traverse<kCount>(ray, counters,
                     [&](const std::uint32_t* primitives, std::uint32_t count, float&) {
                         for (std::uint32_t i = 0; i != count; ++i) {
                             if constexpr (kCount) ++counters.primitives_tested;
                             if (set_->occluded(primitives[i], prepared)) return occluded = true;
                         }
                         return false;
                     });
    return occluded;
}

template <class Set>
bool Bvh<Set>::intersect(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    TraversalCounters unused;
    return intersect_impl<false>(ray, record, scratch, unused);
}

template <class Set>
bool Bvh<Set>::occluded(const Ray& ray, QueryScratch& scratch) const {
    TraversalCounters unused;
    return occluded_impl<false>(ray, scratch, unused);
}

template <class Set>
bool Bvh<Set>::intersect_counted(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                                 TraversalCounters& counters) const {
    return intersect_impl<true>(ray, record, scratch, counters);
}

template <class Set>
bool Bvh<Set>::occluded_counted(const Ray& ray, QueryScratch& scratch,
                                TraversalCounters& counters) const {
    return occluded_impl<true>(ray, scratch, counters);
}

template <class Set>
void Bvh<Set>::all_hits(const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch) const {
    if (set_ == nullptr || !is_valid(ray)) return;
    const auto prepared = set_->prepare(ray, scratch);
    TraversalCounters unused;
    traverse<false>(ray, unused, [&](const std::uint32_t* primitives, std::uint32_t count, float&) {
        for (std::uint32_t i = 0; i != count; ++i) {
            HitRecord record;
            record.t = ray.t_max;
            if (set_->intersect(primitives[i], prepared, record)) hits.push_back(record);
        }
        return false;
    });
}

template class Bvh<TriangleSet<float>>;
template class Bvh<TriangleSet<double>>;
template class Bvh<ShapeSet>;

}  // namespace csgrt
