// Collapsing a binary BVH into 4- or 8-wide nodes (collapse_to_wide, bvh_build.h).

#include <tbb/parallel_for.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "csgrt/accel/bvh_build.h"

namespace csgrt::detail {

namespace {

constexpr float kInfinityFloat = std::numeric_limits<float>::infinity();

/// Levels of wide nodes whose subtrees are collapsed as parallel tasks: up to kWidth^2 tasks,
/// enough to keep a many-core machine busy, few enough that the counts of the first pass
/// (SubtreeSize) are a small tree.
constexpr int kParallelDepth = 2;

/// Half the surface area of a binary node's box in float: the collapse only compares the
/// areas of siblings and cousins, for which float is ample (ties go to the first child).
float node_half_area_float(const BvhNode& node) {
    const float x = node.upper[0] - node.lower[0], y = node.upper[1] - node.lower[1],
                z = node.upper[2] - node.lower[2];
    return x * y + y * z + z * x;
}

/// How many wide nodes a subtree collapses into (its root included), and for a node whose
/// subtrees are collapsed in parallel the same of each interior child, in slot order: the
/// parallel tasks start their numbering where the serial collapse would have reached.
struct SubtreeSize {
    std::uint32_t nodes = 1;
    std::vector<SubtreeSize> children;
};

/// Collapses a binary tree into wide nodes in one layout whatever the scheduling: the serial
/// depth-first order of collapse_to_wide, the top levels in parallel.
template <int kWidth>
class Collapser {
public:
    using Node = WideBvhNode<kWidth>;

    Collapser(const BinaryBvh& binary, bool parallel)
        : nodes_(binary.nodes.data()), parallel_(parallel) {}

    /// The binary nodes a wide node adopts, in slot order, and the interior ones among them.
    struct Children {
        std::uint32_t index[kWidth];
        int count = 0;
        std::uint32_t interior[kWidth];
        int interior_count = 0;
    };

    /// The descendants that the wide node replacing binary node `index` adopts.
    Children children_of(std::uint32_t index) const {
        Children children;
        float areas[kWidth];
        // Leaves are never opened: they get area -1.
        auto area = [&](std::uint32_t child) {
            return nodes_[child].is_leaf() ? -1.0f : node_half_area_float(nodes_[child]);
        };
        auto adopt = [&](std::uint32_t child) {
            children.index[children.count] = child;
            areas[children.count++] = area(child);
        };
        if (nodes_[index].is_leaf()) {
            adopt(index);  // a lone leaf at the root
        } else {
            adopt(nodes_[index].offset);
            adopt(nodes_[index].offset + 1);
        }
        // Open the interior child with the largest box until there are kWidth: it is the one
        // a random ray is most likely to enter, so adopting its children saves the most visits.
        while (children.count < kWidth) {
            int widest = 0;
            for (int i = 1; i < children.count; ++i) {
                if (areas[i] > areas[widest]) widest = i;
            }
            if (areas[widest] < 0.0f) break;
            // The opened node's left child takes its slot, its right child the next free one.
            const std::uint32_t opened = nodes_[children.index[widest]].offset;
            children.index[widest] = opened;
            areas[widest] = area(opened);
            adopt(opened + 1);
        }
        for (int slot = 0; slot < children.count; ++slot) {
            if (!nodes_[children.index[slot]].is_leaf())
                children.interior[children.interior_count++] = children.index[slot];
        }
        return children;
    }

    /// Whether the subtrees below a wide node at `depth` are collapsed as parallel tasks.
    bool fans_out(int depth, const Children& children) const {
        return parallel_ && depth < kParallelDepth && children.interior_count > 1;
    }

    /// The first pass of a parallel collapse: the size of every subtree it hands to a task.
    SubtreeSize count(std::uint32_t index, int depth) const {
        const Children children = children_of(index);
        SubtreeSize size;
        if (!fans_out(depth, children)) {
            size.nodes = count_serial(children);
            return size;
        }
        size.children.resize(std::size_t(children.interior_count));
        tbb::parallel_for(0, children.interior_count, [&](int k) {
            size.children[std::size_t(k)] = count(children.interior[k], depth + 1);
        });
        for (const SubtreeSize& child : size.children) size.nodes += child.nodes;
        return size;
    }

    /// Writes into wide[wide_index] the wide node that replaces binary node `index`, and its
    /// subtree into the nodes from `next_free` on: the node's interior children side by side,
    /// then each child's subtree in slot order. Returns the first index after the subtree.
    /// `size` is the first pass's count of this subtree when its children fan out.
    std::uint32_t collapse(Node* wide, std::uint32_t index, std::uint32_t wide_index,
                           std::uint32_t next_free, int depth, const SubtreeSize* size) const {
        const Children children = children_of(index);
        write_node(wide[wide_index], children, next_free);
        std::uint32_t free = next_free + std::uint32_t(children.interior_count);
        if (size == nullptr || !fans_out(depth, children)) {
            for (int k = 0; k < children.interior_count; ++k)
                free = collapse(wide, children.interior[k], next_free + std::uint32_t(k), free,
                                depth + 1, nullptr);
            return free;
        }
        // Where each child's subtree starts is known from the counts, so the tasks need not
        // share a counter, and the layout is the serial one.
        std::uint32_t starts[kWidth];
        for (int k = 0; k < children.interior_count; ++k) {
            starts[k] = free;
            free += size->children[std::size_t(k)].nodes - 1;
        }
        tbb::parallel_for(0, children.interior_count, [&](int k) {
            collapse(wide, children.interior[k], next_free + std::uint32_t(k), starts[k],
                     depth + 1, &size->children[std::size_t(k)]);
        });
        return free;
    }

private:
    std::uint32_t count_serial(const Children& children) const {
        std::uint32_t nodes = 1;
        for (int k = 0; k < children.interior_count; ++k)
            nodes += count_serial(children_of(children.interior[k]));
        return nodes;
    }

    /// Fills `node` from its adopted children; its interior children are numbered from
    /// `first_child` on in slot order.
    void write_node(Node& node, const Children& children, std::uint32_t first_child) const {
        std::uint32_t next_child = first_child;
        for (int slot = 0; slot < kWidth; ++slot) {
            if (slot >= children.count) {
                for (int axis = 0; axis < 3; ++axis) {
                    node.bounds[2 * axis][slot] = kInfinityFloat;
                    node.bounds[2 * axis + 1][slot] = -kInfinityFloat;
                }
                node.first[slot] = 0;
                node.count[slot] = 0;
                continue;
            }
            const BvhNode& child = nodes_[children.index[slot]];
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
    }

    const BvhNode* nodes_;
    bool parallel_;
};

}  // namespace

template <int kWidth>
WideBvhNodes<kWidth> collapse_to_wide(const BinaryBvh& binary, bool parallel) {
    if (binary.nodes.empty()) return {};
    const Collapser<kWidth> collapser(binary, parallel);
    if (!parallel) {
        // A binary tree of n nodes (n - 1 of them in use: slot 1 is not) collapses into at
        // most n / 2 + 1 wide nodes. The storage for that many is left uninitialised and cut
        // to the nodes made, not copied: pages never written are never touched (see the
        // Bvh's stats).
        WideBvhNodes<kWidth> wide(binary.nodes.size() / 2 + 1);
        wide.resize(collapser.collapse(wide.data(), 0, 0, 1, 0, nullptr));
        return wide;
    }
    // In parallel, a first pass counts the nodes of each subtree a task will write (the same
    // choices as the second, without the writes), so each task knows where its nodes go.
    const SubtreeSize size = collapser.count(0, 0);
    WideBvhNodes<kWidth> wide(size.nodes);
    collapser.collapse(wide.data(), 0, 0, 1, 0, &size);
    return wide;
}

template WideBvhNodes<4> collapse_to_wide<4>(const BinaryBvh&, bool);
template WideBvhNodes<8> collapse_to_wide<8>(const BinaryBvh&, bool);

}  // namespace csgrt::detail
