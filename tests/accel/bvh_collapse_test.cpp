// The collapse of a binary BVH into wide nodes (detail::collapse_to_wide): one layout in
// memory whatever the scheduling, and that layout the documented depth-first one.

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "csgrt/accel/bvh_build.h"
#include "support/random.h"

namespace csgrt {
namespace {

/// `count` random boxes in the unit cube, from 10^-3 to 10^-1 on a side: a tree of
/// thousands of wide nodes, so the parallel collapse really hands subtrees to tasks.
std::vector<detail::BuildPrimitive, AlignedAllocator<detail::BuildPrimitive>> random_boxes(
    std::size_t count, std::uint64_t seed) {
    test::Random random(seed);
    std::vector<detail::BuildPrimitive, AlignedAllocator<detail::BuildPrimitive>> boxes(count);
    for (std::size_t i = 0; i < count; ++i) {
        const float size = float(random.uniform(1e-3, 1e-1));
        for (int axis = 0; axis < 3; ++axis) {
            boxes[i].lower[axis] = float(random.uniform(0.0, 1.0));
            boxes[i].upper[axis] = boxes[i].lower[axis] + size;
        }
        boxes[i].index = std::uint32_t(i);
        boxes[i].unused = 0.0f;
    }
    return boxes;
}

/// Checks the documented order of a collapsed tree independently of the collapser: the root
/// is node 0, a node's interior children are consecutive, and they come right after the
/// subtrees of the nodes before them in a depth-first walk (so the walk, which numbers each
/// node's children when it reaches the node, meets the indices in order 1, 2, 3, ...).
template <int kWidth>
void expect_depth_first_layout(const WideBvhNodes<kWidth>& wide) {
    using Node = WideBvhNode<kWidth>;
    std::uint32_t next = 1;
    std::vector<std::uint32_t> stack = {0};
    std::size_t reached = 1;
    while (!stack.empty()) {
        const Node& node = wide[stack.back()];
        stack.pop_back();
        std::vector<std::uint32_t> interior;
        for (int slot = 0; slot < kWidth; ++slot) {
            if (node.count[slot] != Node::kInterior) continue;
            ASSERT_EQ(node.first[slot], next) << "interior children numbered out of order";
            interior.push_back(next++);
        }
        reached += interior.size();
        // Depth first, in slot order: the first child's subtree is walked first.
        stack.insert(stack.end(), interior.rbegin(), interior.rend());
    }
    EXPECT_EQ(next, wide.size());
    EXPECT_EQ(reached, wide.size()) << "every node is some node's child, once";
}

template <int kWidth>
void expect_parallel_collapse_is_serial(std::size_t count, std::uint64_t seed) {
    auto boxes = random_boxes(count, seed);
    const detail::BinaryBvh binary =
        detail::build_binary_bvh(boxes, BvhConfig{.max_leaf_size = 4, .parallel = false});
    const auto serial = detail::collapse_to_wide<kWidth>(binary, false);
    ASSERT_GT(serial.size(), 1000u);
    expect_depth_first_layout<kWidth>(serial);
    // The wide nodes have no padding (bvh_build.h's static_asserts), so bytes compare.
    for (int threads : {2, 4, 8}) {
        tbb::task_arena arena(threads);
        for (int run = 0; run < 3; ++run) {
            const auto parallel =
                arena.execute([&] { return detail::collapse_to_wide<kWidth>(binary, true); });
            ASSERT_EQ(parallel.size(), serial.size()) << threads << " threads, run " << run;
            EXPECT_EQ(std::memcmp(parallel.data(), serial.data(),
                                  serial.size() * sizeof(WideBvhNode<kWidth>)),
                      0)
                << threads << " threads, run " << run;
        }
    }
}

TEST(BvhCollapse, ParallelCollapseLaysOutTheSerialArrayForWidthFour) {
    expect_parallel_collapse_is_serial<4>(60000, 41);
}

TEST(BvhCollapse, ParallelCollapseLaysOutTheSerialArrayForWidthEight) {
    expect_parallel_collapse_is_serial<8>(60000, 42);
}

TEST(BvhCollapse, LoneLeafAndTinyTreesCollapse) {
    for (std::size_t count : {1u, 2u, 5u, 9u, 40u}) {
        auto boxes = random_boxes(count, 43 + count);
        const detail::BinaryBvh binary =
            detail::build_binary_bvh(boxes, BvhConfig{.max_leaf_size = 1, .parallel = false});
        const auto serial = detail::collapse_to_wide<8>(binary, false);
        const auto parallel = detail::collapse_to_wide<8>(binary, true);
        ASSERT_EQ(parallel.size(), serial.size()) << count << " boxes";
        expect_depth_first_layout<8>(serial);
        EXPECT_EQ(std::memcmp(parallel.data(), serial.data(),
                              serial.size() * sizeof(Bvh8Node)),
                  0)
            << count << " boxes";
        // Every box is in exactly one leaf.
        std::uint32_t primitives = 0;
        for (const auto& node : serial) {
            for (int slot = 0; slot < 8; ++slot) {
                if (node.count[slot] != Bvh8Node::kInterior) primitives += node.count[slot];
            }
        }
        EXPECT_EQ(primitives, count);
    }
}

}  // namespace
}  // namespace csgrt
