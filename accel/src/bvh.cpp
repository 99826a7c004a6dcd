// The BVH's build: the primitives' padded boxes, the binned SAH tree (bvh_build.cpp), its
// leaves' blocks or indices and its wide nodes. The queries are bvh_traversal.cpp (one ray)
// and bvh_packet.cpp (packets of rays).

#include "csgrt/accel/bvh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "bvh_leaf.h"
#include "bvh_ray.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"

namespace csgrt {

namespace {

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
    constexpr bool kBlockSet = detail::kBlockLeaves<Set>;
    const bool blocks = kBlockSet && config.triangle_blocks;
    use_avx2_ = false;
#if CSGRT_BVH_AVX2
    use_avx2_ = config.width == 8 && config.avx2 && __builtin_cpu_supports("avx2") &&
                __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
                __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("popcnt");
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
        detail::build_binary_bvh(primitives, config, blocks ? int(kBvhLeafLaneGroup) : 1);
    primitives = {};

    // Leaves name their contents: their triangles copied in leaf order, or entries of the
    // index array (a one-primitive leaf names its primitive itself). Leaves cover the index
    // array in order, so lanes are handed out in that order too.
    indices_.clear();
    leaf_triangles_ = {};
    if constexpr (kBlockSet) {
        if (blocks) fill_leaf_triangles(set, tree, config.parallel);
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
                   indices_.capacity() * sizeof(std::uint32_t) + leaf_triangles_.bytes();
    stats_.nodes = nodes_4_.size() + nodes_8_.size() + binary_nodes_.size();
    stats_.primitives = stats_.references = set.size();
    char details[240];
    std::snprintf(
        details, sizeof details,
        "width %d, depth %d, %zu leaves (%.2f primitives each), %zu lane groups, SAH cost "
        "%.2f, %d bins, %.1f bytes per primitive%s",
        config.width, tree.depth, tree.leaves,
        tree.leaves ? double(set.size()) / double(tree.leaves) : 0.0,
        leaf_triangles_.lanes.size() / (10 * kBvhLeafLaneGroup), tree.sah_cost, config.bins,
        set.size() ? double(stats_.bytes) / double(set.size()) : 0.0,
        use_avx2_ ? ", AVX2" : "");
    stats_.details = details;
    stats_.build_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
void Bvh<Set>::fill_leaf_triangles(const Set& set, detail::BinaryBvh& tree, bool parallel) {
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
    constexpr std::uint32_t kGroup = kBvhLeafLaneGroup;
    std::vector<std::uint32_t> first_group(leaves.size() + 1, 0);
    for (std::size_t k = 0; k < leaves.size(); ++k) {
        first_group[k + 1] = first_group[k] + (tree.nodes[leaves[k]].count + kGroup - 1) / kGroup;
    }
    // Every lane of every leaf is written below: lanes past a leaf's count get zeros and
    // kNoIndex. The storage is left uninitialised until then.
    leaf_triangles_.lanes.resize(std::size_t{10} * kGroup * first_group.back());
    auto fill = [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
            BvhNode& node = tree.nodes[leaves[k]];
            const std::uint32_t lanes = (first_group[k + 1] - first_group[k]) * kGroup;
            for (std::uint32_t lane = 0; lane != lanes; ++lane) {
                const auto at = BvhLeafTriangles::place(first_group[k], node.count, lane);
                const bool used = lane < node.count;
                const std::uint32_t primitive = used ? tree.indices[node.offset + lane] : kNoIndex;
                float* group = leaf_triangles_.lanes.data() + at.group;
                group[9 * at.width + at.lane] = std::bit_cast<float>(primitive);
                if constexpr (detail::kBlockLeaves<Set>) {
                    for (int corner = 0; corner < 3; ++corner) {
                        for (int axis = 0; axis < 3; ++axis) {
                            group[std::size_t(3 * corner + axis) * at.width + at.lane] =
                                used ? set.corner(primitive, corner)[axis] : 0.0f;
                        }
                    }
                }
            }
            node.offset = first_group[k];
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

template class Bvh<TriangleSet<float>>;
template class Bvh<TriangleSet<double>>;
template class Bvh<ShapeSet>;

}  // namespace csgrt
