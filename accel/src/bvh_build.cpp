#include <tbb/blocked_range.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

#include "csgrt/accel/bvh_build.h"

namespace csgrt::detail {

namespace {

constexpr float kInfinityFloat = std::numeric_limits<float>::infinity();
constexpr int kMaxBins = 256;
/// Below these sizes a subtree is built, or a node binned, on one thread: smaller tasks cost
/// more to schedule than they save.
constexpr std::uint32_t kParallelSubtree = 4096;
constexpr std::uint32_t kParallelBinning = 1u << 16;

/// A float box; trivially constructible so that arrays of bins cost nothing until used.
struct Box {
    float lower[3];
    float upper[3];

    static Box empty() {
        return {{kInfinityFloat, kInfinityFloat, kInfinityFloat},
                {-kInfinityFloat, -kInfinityFloat, -kInfinityFloat}};
    }

    void extend(const float* low, const float* high) {
        for (int axis = 0; axis < 3; ++axis) {
            lower[axis] = std::min(lower[axis], low[axis]);
            upper[axis] = std::max(upper[axis], high[axis]);
        }
    }
    void extend(const Box& box) { extend(box.lower, box.upper); }
    /// Half the surface area, in double so that large boxes do not overflow; the SAH only
    /// uses ratios of areas.
    double half_area() const {
        if (!(lower[0] <= upper[0] && lower[1] <= upper[1] && lower[2] <= upper[2])) return 0.0;
        const double x = double(upper[0]) - lower[0], y = double(upper[1]) - lower[1],
                     z = double(upper[2]) - lower[2];
        return x * y + y * z + z * x;
    }
};

/// The boxes of a range's primitives and of their centroids.
struct RangeBounds {
    Box box = Box::empty();
    Box centroids = Box::empty();

    void add(const BuildPrimitive& primitive) {
        box.extend(primitive.lower, primitive.upper);
        centroids.extend(primitive.centroid, primitive.centroid);
    }
    void join(const RangeBounds& other) {
        box.extend(other.box);
        centroids.extend(other.centroids);
    }
};

/// Maps a centroid coordinate to its bin along one axis. The same arithmetic is used when
/// binning and when partitioning, so both agree on every primitive.
struct BinMapping {
    float origin[3];
    float scale[3];
    int bins;

    BinMapping(const Box& centroids, int bin_count) : bins(bin_count) {
        for (int axis = 0; axis < 3; ++axis) {
            origin[axis] = centroids.lower[axis];
            // A zero, infinite or denormal extent gives a useless or non-finite scale: such
            // an axis is not binned.
            const float extent = centroids.upper[axis] - centroids.lower[axis];
            const float s = float(bin_count) / extent;
            scale[axis] = extent > 0.0f && std::isfinite(s) && s > 0.0f ? s : 0.0f;
        }
    }
    int bin(int axis, float coordinate) const {
        const int b = static_cast<int>((coordinate - origin[axis]) * scale[axis]);
        return std::clamp(b, 0, bins - 1);
    }
};

struct Bins {
    Box boxes[3][kMaxBins];
    std::uint32_t counts[3][kMaxBins];

    /// Only the first `bin_count` bins of each axis are used (and initialised).
    explicit Bins(int bin_count) {
        for (int axis = 0; axis < 3; ++axis) {
            std::fill_n(boxes[axis], bin_count, Box::empty());
            std::fill_n(counts[axis], bin_count, 0u);
        }
    }
    void add(const BinMapping& mapping, const BuildPrimitive& primitive) {
        for (int axis = 0; axis < 3; ++axis) {
            const int b = mapping.bin(axis, primitive.centroid[axis]);
            boxes[axis][b].extend(primitive.lower, primitive.upper);
            ++counts[axis][b];
        }
    }
    void join(const Bins& other, int bin_count) {
        for (int axis = 0; axis < 3; ++axis) {
            for (int b = 0; b < bin_count; ++b) {
                boxes[axis][b].extend(other.boxes[axis][b]);
                counts[axis][b] += other.counts[axis][b];
            }
        }
    }
};

struct Split {
    int axis = -1;
    /// Bins 0 .. bin go left.
    int bin = 0;
    /// Sum over both sides of half area times primitive count.
    double cost = std::numeric_limits<double>::infinity();
};

class Builder {
public:
    Builder(std::span<BuildPrimitive> primitives, const BvhConfig& config, BinaryBvh& tree)
        : primitives_(primitives), config_(config), tree_(tree) {}

    /// Builds the subtree of primitives [begin, end) into node `node`; returns its depth.
    int build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth) {
        const std::uint32_t count = end - begin;
        const RangeBounds bounds = range_bounds(begin, end);
        BvhNode& target = tree_.nodes[node];
        std::copy_n(bounds.box.lower, 3, target.lower);
        std::copy_n(bounds.box.upper, 3, target.upper);

        std::uint32_t middle = begin;
        if (count > 1 && depth < kMaxSahDepth) {
            const Split split = find_split(begin, end, bounds);
            const double leaf_cost = config_.intersection_cost * count;
            const double split_cost = config_.traversal_cost + config_.intersection_cost *
                                                                   split.cost /
                                                                   bounds.box.half_area();
            const bool split_pays = split.axis >= 0 && split_cost < leaf_cost;
            if (split.axis >= 0 && (split_pays || count > std::uint32_t(config_.max_leaf_size))) {
                const BinMapping mapping(bounds.centroids, bins_for(count));
                const auto first_right = std::partition(
                    primitives_.begin() + begin, primitives_.begin() + end,
                    [&](const BuildPrimitive& p) {
                        return mapping.bin(split.axis, p.centroid[split.axis]) <= split.bin;
                    });
                middle = static_cast<std::uint32_t>(first_right - primitives_.begin());
            }
        }
        if (middle == begin && count > std::uint32_t(config_.max_leaf_size)) {
            middle = median_split(begin, end, bounds);
        }
        if (middle == begin || middle == end) {
            target.offset = begin;
            target.count = count;
            leaves_.fetch_add(1, std::memory_order_relaxed);
            return 0;
        }

        const std::uint32_t left = next_node_.fetch_add(2, std::memory_order_relaxed);
        target.offset = left;
        target.count = 0;
        int left_depth = 0, right_depth = 0;
        if (config_.parallel && count > kParallelSubtree) {
            tbb::parallel_invoke([&] { left_depth = build(left, begin, middle, depth + 1); },
                                 [&] { right_depth = build(left + 1, middle, end, depth + 1); });
        } else {
            left_depth = build(left, begin, middle, depth + 1);
            right_depth = build(left + 1, middle, end, depth + 1);
        }
        return 1 + std::max(left_depth, right_depth);
    }

    std::uint32_t node_count() const { return next_node_.load(); }
    std::size_t leaf_count() const { return leaves_.load(); }

private:
    /// Small nodes get fewer bins: the sweep over the bins would otherwise cost more than
    /// binning their few primitives, and with a handful of centroids more bins add nothing.
    int bins_for(std::uint32_t count) const {
        return static_cast<int>(std::min<std::uint32_t>(config_.bins, std::max(4u, count)));
    }

    RangeBounds range_bounds(std::uint32_t begin, std::uint32_t end) const {
        auto add_range = [&](const tbb::blocked_range<std::uint32_t>& range, RangeBounds bounds) {
            for (std::uint32_t i = range.begin(); i != range.end(); ++i) bounds.add(primitives_[i]);
            return bounds;
        };
        if (!config_.parallel || end - begin < kParallelBinning) {
            return add_range({begin, end}, RangeBounds{});
        }
        return tbb::parallel_reduce(tbb::blocked_range<std::uint32_t>(begin, end, 1u << 14),
                                    RangeBounds{}, add_range,
                                    [](RangeBounds a, const RangeBounds& b) {
                                        a.join(b);
                                        return a;
                                    });
    }

    /// The cheapest binned split over all three axes (axis -1 when the centroids coincide).
    Split find_split(std::uint32_t begin, std::uint32_t end, const RangeBounds& bounds) const {
        const int bin_count = bins_for(end - begin);
        const BinMapping mapping(bounds.centroids, bin_count);
        Bins bins(bin_count);
        if (!config_.parallel || end - begin < kParallelBinning) {
            for (std::uint32_t i = begin; i != end; ++i) bins.add(mapping, primitives_[i]);
        } else {
            // Each task bins a chunk into its own bins; the results are summed.
            struct Body {
                const Builder& builder;
                const BinMapping& mapping;
                int bin_count;
                Bins bins;
                Body(const Builder& b, const BinMapping& m, int n)
                    : builder(b), mapping(m), bin_count(n), bins(n) {}
                Body(Body& other, tbb::split)
                    : builder(other.builder),
                      mapping(other.mapping),
                      bin_count(other.bin_count),
                      bins(other.bin_count) {}
                void operator()(const tbb::blocked_range<std::uint32_t>& range) {
                    for (std::uint32_t i = range.begin(); i != range.end(); ++i)
                        bins.add(mapping, builder.primitives_[i]);
                }
                void join(const Body& other) { bins.join(other.bins, bin_count); }
            };
            Body body(*this, mapping, bin_count);
            tbb::parallel_reduce(tbb::blocked_range<std::uint32_t>(begin, end, 1u << 14), body);
            bins = body.bins;
        }

        Split best;
        double right_cost[kMaxBins];
        for (int axis = 0; axis < 3; ++axis) {
            if (mapping.scale[axis] == 0.0f) continue;
            // Sweep from the right, then from the left: cost of splitting after bin b is
            // area(left) count(left) + area(right) count(right).
            Box right = Box::empty();
            std::uint32_t right_count = 0;
            for (int b = bin_count - 1; b > 0; --b) {
                right.extend(bins.boxes[axis][b]);
                right_count += bins.counts[axis][b];
                right_cost[b] = right_count ? right.half_area() * right_count : -1.0;
            }
            Box left = Box::empty();
            std::uint32_t left_count = 0;
            for (int b = 0; b < bin_count - 1; ++b) {
                left.extend(bins.boxes[axis][b]);
                left_count += bins.counts[axis][b];
                if (left_count == 0 || right_cost[b + 1] < 0.0) continue;
                const double cost = left.half_area() * left_count + right_cost[b + 1];
                if (cost < best.cost) best = Split{axis, b, cost};
            }
        }
        return best;
    }

    /// Splits [begin, end) in half by centroid along the longest centroid axis, ties (and
    /// coincident centroids) broken by primitive index so the halves are reproducible.
    std::uint32_t median_split(std::uint32_t begin, std::uint32_t end, const RangeBounds& bounds) {
        int axis = 0;
        float longest = -1.0f;
        for (int a = 0; a < 3; ++a) {
            const float extent = bounds.centroids.upper[a] - bounds.centroids.lower[a];
            if (extent > longest) longest = extent, axis = a;
        }
        const std::uint32_t middle = begin + (end - begin) / 2;
        std::nth_element(primitives_.begin() + begin, primitives_.begin() + middle,
                         primitives_.begin() + end,
                         [axis](const BuildPrimitive& a, const BuildPrimitive& b) {
                             if (a.centroid[axis] != b.centroid[axis])
                                 return a.centroid[axis] < b.centroid[axis];
                             return a.index < b.index;
                         });
        return middle;
    }

    std::span<BuildPrimitive> primitives_;
    const BvhConfig& config_;
    BinaryBvh& tree_;
    /// Node 0 is the root and node 1 is unused, so sibling pairs start at even indices.
    std::atomic<std::uint32_t> next_node_{2};
    std::atomic<std::size_t> leaves_{0};
};

double sah_cost(const BinaryBvh& tree, const BvhConfig& config) {
    auto half_area = [](const BvhNode& node) {
        Box box = Box::empty();
        box.extend(node.lower, node.upper);
        return box.half_area();
    };
    double total = 0.0;
    for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
        if (i == 1) continue;
        const BvhNode& node = tree.nodes[i];
        total += half_area(node) *
                 (node.is_leaf() ? config.intersection_cost * node.count : config.traversal_cost);
    }
    const double root_area = half_area(tree.nodes[0]);
    return root_area > 0.0 ? total / root_area : 0.0;
}

/// Appends the 4-wide node that replaces binary node `index` and, depth first, its subtree;
/// returns the new node's index.
std::uint32_t collapse_node(const BinaryBvh& binary, std::uint32_t index,
                            std::vector<Bvh4Node>& wide) {
    const auto& nodes = binary.nodes;
    std::array<std::uint32_t, 4> children{};
    int child_count = 0;
    if (nodes[index].is_leaf()) {
        children[child_count++] = index;  // a lone leaf at the root
    } else {
        children[child_count++] = nodes[index].offset;
        children[child_count++] = nodes[index].offset + 1;
    }
    // Open the interior child with the largest box until there are four: it is the one a
    // random ray is most likely to enter, so adopting its children saves the most visits.
    while (child_count < 4) {
        int widest = -1;
        double widest_area = -1.0;
        for (int i = 0; i < child_count; ++i) {
            const BvhNode& child = nodes[children[i]];
            if (child.is_leaf()) continue;
            Box box = Box::empty();
            box.extend(child.lower, child.upper);
            if (box.half_area() > widest_area) widest_area = box.half_area(), widest = i;
        }
        if (widest < 0) break;
        const std::uint32_t opened = children[widest];
        children[widest] = nodes[opened].offset;
        children[child_count++] = nodes[opened].offset + 1;
    }

    const auto wide_index = static_cast<std::uint32_t>(wide.size());
    wide.emplace_back();
    for (int slot = 0; slot < 4; ++slot) {
        Bvh4Node& node = wide[wide_index];
        if (slot >= child_count) {
            for (int axis = 0; axis < 3; ++axis) {
                node.bounds[2 * axis][slot] = kInfinityFloat;
                node.bounds[2 * axis + 1][slot] = -kInfinityFloat;
            }
            node.first[slot] = 0;
            node.count[slot] = 0;
            continue;
        }
        const BvhNode& child = nodes[children[slot]];
        for (int axis = 0; axis < 3; ++axis) {
            node.bounds[2 * axis][slot] = child.lower[axis];
            node.bounds[2 * axis + 1][slot] = child.upper[axis];
        }
        if (child.is_leaf()) {
            node.first[slot] = child.offset;
            node.count[slot] = child.count;
        } else {
            node.count[slot] = Bvh4Node::kInterior;
            // The recursion may grow `wide`, so the node is looked up again afterwards.
            const std::uint32_t first = collapse_node(binary, children[slot], wide);
            wide[wide_index].first[slot] = first;
        }
    }
    return wide_index;
}

}  // namespace

std::vector<Bvh4Node> collapse_to_4_wide(const BinaryBvh& binary) {
    std::vector<Bvh4Node> wide;
    if (binary.nodes.empty()) return wide;
    wide.reserve(binary.nodes.size() / 2 + 1);
    collapse_node(binary, 0, wide);
    wide.shrink_to_fit();
    return wide;
}

BinaryBvh build_binary_bvh(std::span<BuildPrimitive> primitives, const BvhConfig& config) {
    BinaryBvh tree;
    if (primitives.empty()) return tree;
    // A binary tree over n primitives has at most n - 1 interior nodes, so 2 n slots hold the
    // root, the unused slot and every sibling pair.
    tree.nodes.resize(2 * primitives.size());
    Builder builder(primitives, config, tree);
    tree.depth = builder.build(0, 0, static_cast<std::uint32_t>(primitives.size()), 0);
    tree.nodes.resize(primitives.size() == 1 ? 1 : builder.node_count());
    tree.nodes.shrink_to_fit();
    tree.leaves = builder.leaf_count();
    tree.indices.resize(primitives.size());
    for (std::size_t i = 0; i < primitives.size(); ++i) tree.indices[i] = primitives[i].index;
    tree.sah_cost = sah_cost(tree, config);
    return tree;
}

}  // namespace csgrt::detail
