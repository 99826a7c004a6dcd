// Collapsing a binary BVH into 4- or 8-wide nodes (collapse_to_wide, bvh_build.h).

#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdint>
#include <limits>

#include "csgrt/accel/bvh_build.h"

namespace csgrt::detail {

namespace {

constexpr float kInfinityFloat = std::numeric_limits<float>::infinity();

/// Half the surface area of a binary node's box in float: collapse_node only compares the
/// areas of siblings and cousins, for which float is ample (ties go to the first child).
float node_half_area_float(const BvhNode& node) {
    const float x = node.upper[0] - node.lower[0], y = node.upper[1] - node.lower[1],
                z = node.upper[2] - node.lower[2];
    return x * y + y * z + z * x;
}

/// Collapses a binary tree into wide nodes, depth first from the root, the top levels in
/// parallel (see collapse_to_wide).
template <int kWidth>
class Collapser {
public:
    using Node = WideBvhNode<kWidth>;

    Collapser(const BinaryBvh& binary, Node* wide, bool parallel)
        : nodes_(binary.nodes.data()), wide_(wide), parallel_(parallel) {}

    /// Writes into wide[wide_index] the wide node that replaces binary node `index`, then
    /// its subtree.
    void collapse(std::uint32_t index, std::uint32_t wide_index, int depth) {
        std::uint32_t children[kWidth];
        float areas[kWidth];
        int child_count = 0;
        // Leaves are never opened: they get area -1.
        auto area = [&](std::uint32_t child) {
            return nodes_[child].is_leaf() ? -1.0f : node_half_area_float(nodes_[child]);
        };
        auto adopt = [&](std::uint32_t child) {
            children[child_count] = child;
            areas[child_count++] = area(child);
        };
        if (nodes_[index].is_leaf()) {
            adopt(index);  // a lone leaf at the root
        } else {
            adopt(nodes_[index].offset);
            adopt(nodes_[index].offset + 1);
        }
        // Open the interior child with the largest box until there are kWidth: it is the one
        // a random ray is most likely to enter, so adopting its children saves the most visits.
        while (child_count < kWidth) {
            int widest = 0;
            for (int i = 1; i < child_count; ++i) {
                if (areas[i] > areas[widest]) widest = i;
            }
            if (areas[widest] < 0.0f) break;
            // The opened node's left child takes its slot, its right child the next free one.
            const std::uint32_t opened = nodes_[children[widest]].offset;
            children[widest] = opened;
            areas[widest] = area(opened);
            adopt(opened + 1);
        }

        int interior = 0;
        for (int slot = 0; slot < child_count; ++slot)
            interior += !nodes_[children[slot]].is_leaf();
        // A node's interior children are allocated side by side.
        const std::uint32_t first_child =
            interior ? next_.fetch_add(std::uint32_t(interior), std::memory_order_relaxed) : 0u;
        Node& node = wide_[wide_index];
        std::uint32_t next_child = first_child;
        for (int slot = 0; slot < kWidth; ++slot) {
            if (slot >= child_count) {
                for (int axis = 0; axis < 3; ++axis) {
                    node.bounds[2 * axis][slot] = kInfinityFloat;
                    node.bounds[2 * axis + 1][slot] = -kInfinityFloat;
                }
                node.first[slot] = 0;
                node.count[slot] = 0;
                continue;
            }
            const BvhNode& child = nodes_[children[slot]];
            for (int axis = 0; axis < 3; ++axis) {
                node.bounds[2 * axis][slot] = child.lower[axis];
                node.bounds[2 * axis + 1][slot] = child.upper[axis];
            }
            if (child.is_leaf()) {
                node.first[slot] = child.offset;
                node.count[slot] = child.count;
            } else {
                node.first[slot] = next_child++;
                node.count[slot] = Node::kInterior;
            }
        }

        // The top levels (up to kWidth^3 subtrees) are collapsed as parallel tasks.
        auto descend = [&](int slot) {
            if (slot < child_count && node.count[slot] == Node::kInterior)
                collapse(children[slot], node.first[slot], depth + 1);
        };
        if (parallel_ && depth < 3 && interior > 1) {
            tbb::parallel_for(0, kWidth, descend);
        } else {
            for (int slot = 0; slot < kWidth; ++slot) descend(slot);
        }
    }

    std::uint32_t node_count() const { return next_.load(); }

private:
    const BvhNode* nodes_;
    Node* wide_;
    bool parallel_;
    /// The root is wide node 0.
    std::atomic<std::uint32_t> next_{1};
};

}  // namespace

template <int kWidth>
WideBvhNodes<kWidth> collapse_to_wide(const BinaryBvh& binary, bool parallel) {
    if (binary.nodes.empty()) return {};
    // A binary tree of n nodes (n - 1 of them in use: slot 1 is not) collapses into at most
    // n / 2 + 1 wide nodes. The storage for that many is left uninitialised and cut to the
    // nodes made, not copied: pages never written are never touched (see the Bvh's stats).
    WideBvhNodes<kWidth> wide(binary.nodes.size() / 2 + 1);
    Collapser<kWidth> collapser(binary, wide.data(), parallel);
    collapser.collapse(0, 0, 0);
    wide.resize(collapser.node_count());
    return wide;
}

template WideBvhNodes<4> collapse_to_wide<4>(const BinaryBvh&, bool);
template WideBvhNodes<8> collapse_to_wide<8>(const BinaryBvh&, bool);

}  // namespace csgrt::detail
