// The binned SAH build of a binary BVH (build_binary_bvh, bvh_build.h) and the aligned storage
// of the BVHs' arrays. Collapsing it into wide nodes is bvh_collapse.cpp.

#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <new>

#include "bvh_simd.h"
#include "csgrt/accel/bvh_build.h"

// GCC says __SANITIZE_ADDRESS__, clang __has_feature(address_sanitizer).
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CSGRT_ADDRESS_SANITIZER 1
#endif
#endif

namespace csgrt::detail {

namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;

/// Whether a block is large enough to be worth huge pages (two of them at least, so the
/// rounding waste stays small). Not under AddressSanitizer, whose allocator would be handed
/// an alignment it does not need and whose pages are its own business.
bool use_huge_pages(std::size_t bytes) {
#if defined(__SANITIZE_ADDRESS__) || defined(CSGRT_ADDRESS_SANITIZER)
    (void)bytes;
    return false;
#else
    return bytes >= 2 * kHugePage;
#endif
}

constexpr float kInfinityFloat = std::numeric_limits<float>::infinity();
constexpr int kMaxBins = 256;
/// Below this size a subtree is built on one thread: smaller tasks cost more to schedule than
/// they save.
constexpr std::uint32_t kParallelSubtree = 4096;
/// Nodes larger than this find their split on a sample of their primitives.
constexpr std::uint32_t kSampledBinning = 1u << 12;

/// A float box in two SIMD registers (the fourth lane is unused).
struct Box {
    Float4 lower;
    Float4 upper;

    static Box empty() {
        return {Float4::broadcast(kInfinityFloat), Float4::broadcast(-kInfinityFloat)};
    }
    static Box of(const BuildPrimitive& p) {
        return {Float4::load(p.lower), Float4::load(p.upper)};
    }
    // The new value is the first operand: a NaN in it (the centre of an unbounded box) is
    // ignored rather than spread.
    void extend(const Box& box) {
        lower = min(box.lower, lower);
        upper = max(box.upper, upper);
    }
    void extend(Float4 point) {
        lower = min(point, lower);
        upper = max(point, upper);
    }
    void store(float* low, float* high) const {
        float l[4], h[4];
        lower.store(l);
        upper.store(h);
        std::copy_n(l, 3, low);
        std::copy_n(h, 3, high);
    }
    /// Half the surface area, in double so that large boxes do not overflow; the SAH only
    /// uses ratios of areas.
    double half_area() const {
        float l[4], h[4];
        lower.store(l);
        upper.store(h);
        if (!(l[0] <= h[0] && l[1] <= h[1] && l[2] <= h[2])) return 0.0;
        const double x = double(h[0]) - l[0], y = double(h[1]) - l[1], z = double(h[2]) - l[2];
        return x * y + y * z + z * x;
    }
    /// Half the surface area of the box scaled by `scale` (all lanes equal), in float; the box
    /// must not be empty.
    float scaled_half_area(Float4 scale) const {
        const Float4 extent = (upper - lower) * scale;
        return (extent * extent.rotate()).sum3();
    }
};

/// Twice the centre of a primitive's box: binning only needs it up to scale.
Float4 doubled_centroid(const BuildPrimitive& p) {
    return Float4::load(p.lower) + Float4::load(p.upper);
}

/// A range of primitives with its box and the box of its (doubled) centroids.
struct Range {
    std::uint32_t begin, end;
    Box box;
    Box centroids;
};

/// Maps doubled centroids to bins, on all three axes at once. The same arithmetic is used when
/// binning and when partitioning, so both agree on every primitive.
struct BinMapping {
    Float4 origin, scale, last;
    float origins[4], scales[4];

    BinMapping(const Box& centroids, int bin_count) {
        float l[4], h[4];
        centroids.lower.store(l);
        centroids.upper.store(h);
        for (int axis = 0; axis < 3; ++axis) {
            // A zero, infinite or denormal extent gives a useless or non-finite scale: such
            // an axis is not binned.
            const float extent = h[axis] - l[axis];
            const float s = float(bin_count) / extent;
            scales[axis] = extent > 0.0f && std::isfinite(s) && s > 0.0f ? s : 0.0f;
            if (!std::isfinite(l[axis])) l[axis] = 0.0f;
        }
        l[3] = 0.0f;
        scales[3] = 0.0f;
        std::copy_n(l, 4, origins);
        origin = Float4::load(l);
        scale = Float4::load(scales);
        last = Float4::broadcast(float(bin_count - 1));
    }
    /// The bins of a primitive on the three axes (and a fourth, unused).
    void bins(const BuildPrimitive& p, int* out) const {
        // max(x, 0) returns 0 for NaN (the centre of an unbounded box) and min clamps to the
        // last bin, so the truncation always sees a value in [0, bins - 1].
        const Float4 position = (doubled_centroid(p) - origin) * scale;
        min(max(position, Float4::broadcast(0.0f)), last).truncate(out);
    }
    /// Whether the primitive's bin on `axis` is at most `bin`: bins() computes the position
    /// with the same float operations and truncates it after clamping it to [0, bins - 1],
    /// which gives a bin > `bin` exactly when the position is >= bin + 1 (a NaN position
    /// goes to bin 0).
    bool bin_at_most(const BuildPrimitive& p, int axis, int bin) const {
        const float position = (p.lower[axis] + p.upper[axis] - origins[axis]) * scales[axis];
        return !(position >= float(bin + 1));
    }
};

struct Bins {
    Box boxes[3][kMaxBins];
    /// counts[bin][axis], as floats so the sweep loads a bin's three counts as one Float4;
    /// whole numbers below 2^24 (at most kSampledBinning primitives are binned), so exact.
    alignas(16) float counts[kMaxBins][4];
    int bin_count;

    /// Only the first `bin_count` bins of each axis are used (and initialised).
    explicit Bins(int n) : bin_count(n) {
        for (int axis = 0; axis < 3; ++axis) std::fill_n(boxes[axis], n, Box::empty());
        std::fill_n(&counts[0][0], 4 * n, 0.0f);
    }
    void add(const BinMapping& mapping, const BuildPrimitive& primitive) {
        alignas(16) int bin[4];
        mapping.bins(primitive, bin);
        const Box box = Box::of(primitive);
        for (int axis = 0; axis < 3; ++axis) {
            boxes[axis][bin[axis]].extend(box);
            counts[bin[axis]][axis] += 1.0f;
        }
    }
};

struct Split {
    int axis = -1;
    /// Bins 0 .. bin go left.
    int bin = 0;
    /// Sum over both sides of half area times primitive tests (relative to the node's half
    /// area once find_split returns it).
    float cost = std::numeric_limits<float>::infinity();
};

/// What a subtree's build returns: its depth and its unnormalised SAH cost (the sum over
/// its nodes of half area times the node's cost).
struct Subtree {
    int depth = 0;
    double cost = 0.0;
};

class Builder {
public:
    Builder(std::span<BuildPrimitive> primitives, const BvhConfig& config, int leaf_block,
            BvhNode* nodes)
        : primitives_(primitives),
          config_(config),
          leaf_block_shift_(std::countr_zero(unsigned(leaf_block))),
          nodes_(nodes) {}

    /// The number of primitive tests a leaf of `count` primitives costs (a shift, not a
    /// division: the sweep calls this for every bin).
    std::uint32_t tests(std::uint32_t count) const {
        return (count + (1u << leaf_block_shift_) - 1) >> leaf_block_shift_;
    }

    /// The box and centroid box of all primitives, for the root (in parallel chunks when the
    /// config says so: min and max give the same boxes in any order).
    Range root() const {
        using Chunk = tbb::blocked_range<std::size_t>;
        auto bound = [&](const Chunk& chunk, Range range) {
            for (std::size_t i = chunk.begin(); i != chunk.end(); ++i) {
                range.box.extend(Box::of(primitives_[i]));
                range.centroids.extend(doubled_centroid(primitives_[i]));
            }
            return range;
        };
        const Range empty{0, static_cast<std::uint32_t>(primitives_.size()), Box::empty(),
                          Box::empty()};
        const Chunk all(0, primitives_.size(), 1u << 14);
        if (!config_.parallel) return bound(all, empty);
        return tbb::parallel_reduce(all, empty, bound, [](Range a, const Range& b) {
            a.box.extend(b.box);
            a.centroids.extend(b.centroids.lower);
            a.centroids.extend(b.centroids.upper);
            return a;
        });
    }

    /// Builds the subtree of `range` into node `node`; returns its depth.
    /// Builds the subtree of `range` at node `node`; returns its depth and SAH cost.
    Subtree build(std::uint32_t node, const Range& range, int depth) {
        const std::uint32_t count = range.end - range.begin;
        BvhNode& target = nodes_[node];
        range.box.store(target.lower, target.upper);

        Range left, right;
        bool split = false;
        if (tests(count) == 1 && count <= std::uint32_t(config_.max_leaf_size) &&
            config_.traversal_cost >= config_.intersection_cost) {
            // A leaf of one test costs intersection_cost; any split costs at least
            // traversal_cost, which is no less, so the SAH keeps the leaf: no need to bin.
        } else if (count == 2 && depth < kMaxSahDepth && !coincident(range.centroids)) {
            // Two primitives allow one split, whose SAH cost needs no bins: this is the most
            // common node near the leaves.
            const BuildPrimitive* pair = primitives_.data() + range.begin;
            const Box a = Box::of(pair[0]), b = Box::of(pair[1]);
            const double split_cost = config_.traversal_cost + config_.intersection_cost *
                                                                   (a.half_area() + b.half_area()) /
                                                                   range.box.half_area();
            if (split_cost < config_.intersection_cost * tests(2) || config_.max_leaf_size < 2) {
                left = {range.begin, range.begin + 1, a, Box::empty()};
                right = {range.begin + 1, range.end, b, Box::empty()};
                left.centroids.extend(doubled_centroid(pair[0]));
                right.centroids.extend(doubled_centroid(pair[1]));
                split = true;
            }
        } else if (count > 1 && depth < kMaxSahDepth) {
            const int bin_count = bins_for(count);
            const BinMapping mapping(range.centroids, bin_count);
            const Split best = find_split(range, mapping, bin_count);
            const double leaf_cost = config_.intersection_cost * tests(count);
            const double split_cost =
                config_.traversal_cost + config_.intersection_cost * best.cost;
            const bool split_pays = best.axis >= 0 && split_cost < leaf_cost;
            if (best.axis >= 0 && (split_pays || count > std::uint32_t(config_.max_leaf_size))) {
                partition(range, mapping, best, left, right);
                split = true;
            }
        }
        if (!split && count > std::uint32_t(config_.max_leaf_size)) {
            median_split(range, left, right);
            split = true;
        }
        if (!split) {
            target.offset = range.begin;
            target.count = count;
            leaves_.fetch_add(1, std::memory_order_relaxed);
            return {0, range.box.half_area() * config_.intersection_cost * tests(count)};
        }

        const std::uint32_t first = next_node_.fetch_add(2, std::memory_order_relaxed);
        target.offset = first;
        target.count = 0;
        Subtree left_tree, right_tree;
        if (config_.parallel && count > kParallelSubtree) {
            tbb::parallel_invoke([&] { left_tree = build(first, left, depth + 1); },
                                 [&] { right_tree = build(first + 1, right, depth + 1); });
        } else {
            left_tree = build(first, left, depth + 1);
            right_tree = build(first + 1, right, depth + 1);
        }
        // Summed in the same order whatever the threads did, so the cost is reproducible.
        return {1 + std::max(left_tree.depth, right_tree.depth),
                range.box.half_area() * config_.traversal_cost + left_tree.cost + right_tree.cost};
    }

    std::uint32_t node_count() const { return next_node_.load(); }
    std::size_t leaf_count() const { return leaves_.load(); }

private:
    /// Whether all centroids are one point (no split by centroid can separate them).
    static bool coincident(const Box& centroids) {
        float l[4], h[4];
        centroids.lower.store(l);
        centroids.upper.store(h);
        return !(l[0] < h[0] || l[1] < h[1] || l[2] < h[2]);
    }

    /// Small nodes get fewer bins: the sweep over the bins would otherwise cost more than
    /// binning their few primitives, and with a handful of centroids more bins add nothing.
    int bins_for(std::uint32_t count) const {
        return static_cast<int>(std::min<std::uint32_t>(config_.bins, std::max(4u, count)));
    }

    /// The cheapest binned split over all three axes (axis -1 when the centroids coincide).
    Split find_split(const Range& range, const BinMapping& mapping, int bin_count) const {
        // Nodes of more than kSampledBinning primitives bin an evenly strided sample of
        // kSampledBinning / 2 to kSampledBinning of them: the bins' counts and boxes are then
        // estimates, which pick the split plane about as well, while binning costs a fraction
        // (the partition still moves and bounds every primitive). The approximation is that of
        // Hunt, Mark and Stoll, "Fast kd-tree Construction with an Adaptive Error-Bounded
        // Heuristic", 2006.
        Bins bins(bin_count);
        const std::uint32_t count = range.end - range.begin;
        const std::uint32_t stride = count > kSampledBinning ? count / (kSampledBinning / 2) : 1u;
        for (std::uint32_t i = range.begin; i < range.end; i += stride)
            bins.add(mapping, primitives_[i]);

        // The sweep computes areas in float, on extents scaled by a power of two that brings
        // the node's largest extent just below 1: no product overflows, and scaling by a power
        // of two loses no precision.
        float lower[4], upper[4];
        range.box.lower.store(lower);
        range.box.upper.store(upper);
        const float largest =
            std::max({upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2]});
        const int exponent = largest > 0.0f && std::isfinite(largest) ? std::ilogb(largest) + 1 : 0;
        const Float4 scale = Float4::broadcast(std::ldexp(1.0f, std::clamp(-exponent, -126, 126)));
        const float node_area = range.box.scaled_half_area(scale);

        // The three axes are swept at once, lane a of each Float4 below for axis a: the cost
        // of splitting after bin b is area(left) tests(left) + area(right) tests(right), +inf
        // when a side is empty.
        const Float4 infinity = Float4::broadcast(kInfinityFloat);
        const Float4 zero = Float4::broadcast(0.0f);
        // A leaf of n costs ceil(n / block) tests, computed as trunc((n + block - 1) / block):
        // the counts are integers well inside float's exact range.
        const float block = float(1u << leaf_block_shift_);
        const Float4 round_up = Float4::broadcast(block - 1.0f);
        const Float4 per_block = Float4::broadcast(1.0f / block);
        auto side_cost = [&](const Box sides[3], Float4 counts) {
            Float4 x, y, z;
            transpose3((sides[0].upper - sides[0].lower) * scale,
                       (sides[1].upper - sides[1].lower) * scale,
                       (sides[2].upper - sides[2].lower) * scale, x, y, z);
            const Float4 area = x * y + y * z + z * x;
            const Float4 cost = area * ((counts + round_up) * per_block).truncated();
            const Float4 filled = zero < counts;
            return (filled & cost) | and_not(filled, infinity);
        };
        auto counts_at = [&](int b) { return Float4::load_aligned(bins.counts[b]); };
        Float4 right_cost[kMaxBins];
        Box right[3] = {Box::empty(), Box::empty(), Box::empty()};
        Float4 right_count = zero;
        for (int b = bin_count - 1; b > 0; --b) {
            for (int axis = 0; axis < 3; ++axis) right[axis].extend(bins.boxes[axis][b]);
            right_count = right_count + counts_at(b);
            right_cost[b] = side_cost(right, right_count);
        }
        Box left[3] = {Box::empty(), Box::empty(), Box::empty()};
        Float4 left_count = zero;
        Float4 best_cost = infinity, best_bin = zero;
        for (int b = 0; b < bin_count - 1; ++b) {
            for (int axis = 0; axis < 3; ++axis) left[axis].extend(bins.boxes[axis][b]);
            left_count = left_count + counts_at(b);
            const Float4 cost = side_cost(left, left_count) + right_cost[b + 1];
            // Strictly less: ties keep the lowest bin, as do ties between axes below.
            const Float4 better = cost < best_cost;
            best_cost = min(cost, best_cost);
            best_bin = (better & Float4::broadcast(float(b))) | and_not(better, best_bin);
        }
        float costs[4], bins_found[4];
        best_cost.store(costs);
        best_bin.store(bins_found);
        Split best;
        for (int axis = 0; axis < 3; ++axis) {
            if (mapping.scales[axis] != 0.0f && costs[axis] < best.cost)
                best = Split{axis, int(bins_found[axis]), costs[axis]};
        }
        // Relative to the node's area, as the SAH wants it.
        if (best.axis >= 0) best.cost = node_area > 0.0f ? best.cost / node_area : 0.0f;
        return best;
    }

    /// Moves the primitives of bins 0 .. split.bin to the front of the range, computing both
    /// sides' boxes on the way.
    void partition(const Range& range, const BinMapping& mapping, const Split& split, Range& left,
                   Range& right) {
        auto goes_left = [&](const BuildPrimitive& p) {
            return mapping.bin_at_most(p, split.axis, split.bin);
        };
        left = {range.begin, range.begin, Box::empty(), Box::empty()};
        right = {range.end, range.end, Box::empty(), Box::empty()};
        BuildPrimitive* i = primitives_.data() + range.begin;
        BuildPrimitive* j = primitives_.data() + range.end;
        for (;;) {
            while (i != j && goes_left(*i)) {
                left.box.extend(Box::of(*i));
                left.centroids.extend(doubled_centroid(*i));
                ++i;
            }
            while (i != j && !goes_left(*(j - 1))) {
                --j;
                right.box.extend(Box::of(*j));
                right.centroids.extend(doubled_centroid(*j));
            }
            if (i == j) break;
            // *i belongs right and *(j - 1) left: exchange them and count both.
            --j;
            std::swap(*i, *j);
            left.box.extend(Box::of(*i));
            left.centroids.extend(doubled_centroid(*i));
            ++i;
            right.box.extend(Box::of(*j));
            right.centroids.extend(doubled_centroid(*j));
        }
        left.end = right.begin = static_cast<std::uint32_t>(i - primitives_.data());
    }

    /// Splits the range in half by centroid along the longest centroid axis, ties (and
    /// coincident centroids) broken by primitive index so the halves are reproducible.
    void median_split(const Range& range, Range& left, Range& right) {
        float l[4], h[4];
        range.centroids.lower.store(l);
        range.centroids.upper.store(h);
        int axis = 0;
        float longest = -1.0f;
        for (int a = 0; a < 3; ++a) {
            const float extent = h[a] - l[a];
            if (extent > longest) longest = extent, axis = a;
        }
        auto key = [axis](const BuildPrimitive& p) {
            const float c = p.lower[axis] + p.upper[axis];
            return std::isnan(c) ? 0.0f : c;
        };
        const std::uint32_t middle = range.begin + (range.end - range.begin) / 2;
        std::nth_element(primitives_.begin() + range.begin, primitives_.begin() + middle,
                         primitives_.begin() + range.end,
                         [&](const BuildPrimitive& a, const BuildPrimitive& b) {
                             const float ka = key(a), kb = key(b);
                             return ka != kb ? ka < kb : a.index < b.index;
                         });
        left = {range.begin, middle, Box::empty(), Box::empty()};
        right = {middle, range.end, Box::empty(), Box::empty()};
        for (Range* side : {&left, &right}) {
            for (std::uint32_t k = side->begin; k != side->end; ++k) {
                side->box.extend(Box::of(primitives_[k]));
                side->centroids.extend(doubled_centroid(primitives_[k]));
            }
        }
    }

    std::span<BuildPrimitive> primitives_;
    const BvhConfig& config_;
    int leaf_block_shift_;
    BvhNode* nodes_;
    /// Node 0 is the root and node 1 is unused, so sibling pairs start at even indices.
    std::atomic<std::uint32_t> next_node_{2};
    std::atomic<std::size_t> leaves_{0};
};

}  // namespace

void* allocate_aligned(std::size_t bytes, std::size_t alignment) {
    if (!use_huge_pages(bytes)) return ::operator new(bytes, std::align_val_t(alignment));
    void* pointer = ::operator new(bytes, std::align_val_t(std::max(alignment, kHugePage)));
    // Advice only: where the kernel has no huge pages (or no THP), nothing changes.
    madvise(pointer, bytes, MADV_HUGEPAGE);
    return pointer;
}

void deallocate_aligned(void* pointer, std::size_t bytes, std::size_t alignment) noexcept {
    ::operator delete(
        pointer,
        std::align_val_t(use_huge_pages(bytes) ? std::max(alignment, kHugePage) : alignment));
}

BinaryBvh build_binary_bvh(std::span<BuildPrimitive> primitives, const BvhConfig& config,
                           int leaf_block) {
    BinaryBvh tree;
    if (primitives.empty()) return tree;
    // A binary tree over n primitives has at most n - 1 interior nodes, so 2 n slots hold the
    // root, the unused slot and every sibling pair. They are left uninitialised and the vector
    // is cut to the nodes made, not copied: a tree has about 2 n / (primitives per leaf) nodes,
    // and only the pages written are ever touched.
    tree.nodes.resize(2 * primitives.size());
    tree.nodes[1] = BvhNode{};
    Builder builder(primitives, config, leaf_block, tree.nodes.data());
    const Range root = builder.root();
    const Subtree built = builder.build(0, root, 0);
    tree.nodes.resize(primitives.size() == 1 ? 1 : builder.node_count());
    tree.depth = built.depth;
    tree.leaves = builder.leaf_count();
    tree.indices.resize(primitives.size());
    auto copy_indices = [&](const tbb::blocked_range<std::size_t>& chunk) {
        for (std::size_t i = chunk.begin(); i != chunk.end(); ++i)
            tree.indices[i] = primitives[i].index;
    };
    const tbb::blocked_range<std::size_t> all(0, primitives.size(), 1u << 14);
    if (config.parallel) {
        tbb::parallel_for(all, copy_indices);
    } else {
        copy_indices(all);
    }
    const double root_area = root.box.half_area();
    tree.sah_cost = root_area > 0.0 ? built.cost / root_area : 0.0;
    return tree;
}

}  // namespace csgrt::detail
