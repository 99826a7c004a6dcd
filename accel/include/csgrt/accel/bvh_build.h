#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <new>
#include <span>
#include <utility>
#include <vector>

#include "csgrt/accel/accelerator_config.h"

namespace csgrt {


/// A binary BVH node in 32 bytes: a float box and either two children, stored side by side
/// at `offset` and `offset + 1` (count == 0), or a leaf of `count` primitives that are
/// entries offset .. offset + count - 1 of the primitive index array. The root is node 0;
/// node 1 is unused, so each pair of siblings starts at an even index and shares one 64-byte
/// cache line.
struct BvhNode {
    float lower[3];
    std::uint32_t offset;
    float upper[3];
    std::uint32_t count;

    bool is_leaf() const { return count != 0; }
};
static_assert(sizeof(BvhNode) == 32);

/// A wide node of kWidth (4 or 8) children: their boxes as structure of arrays
/// (bounds[2 axis] = lower, bounds[2 axis + 1] = upper, one lane per child; 4 or 8 boxes per
/// SIMD test), and per child a reference: count == kInterior names the wide node `first`;
/// count == 0 is an unused slot, whose empty box (lower = +inf, upper = -inf) no slab test
/// hits; any other count is a leaf of that many primitives starting at `first` (see
/// Bvh::binary_nodes for what `first` names). 128 bytes (two cache lines) for 4 children, 256
/// for 8.
template <int kWidth>
struct alignas(64) WideBvhNode {
    static constexpr std::uint32_t kInterior = 0xffffffffu;
    static constexpr int kChildren = kWidth;

    float bounds[6][kWidth];
    std::uint32_t first[kWidth];
    std::uint32_t count[kWidth];
};
using Bvh4Node = WideBvhNode<4>;
using Bvh8Node = WideBvhNode<8>;
static_assert(sizeof(Bvh4Node) == 128 && sizeof(Bvh8Node) == 256);

/// Four lanes: a leaf of n triangles in a BvhLeafTriangles owns ceil(n / 4) of them, and the
/// SAH prices it by that count.
inline constexpr std::uint32_t kBvhLeafLaneGroup = 4;

namespace detail {
/// Storage aligned to `alignment` bytes; blocks of 4 MiB and more are aligned to 2 MiB and
/// marked for transparent huge pages (Linux madvise), as Embree does for its BVH arrays: a
/// 3.3M-triangle build writes some 300 MB of fresh memory, and faulting it in 2 MiB pages
/// instead of 4 KiB ones saves the build tens of milliseconds of kernel time.
void* allocate_aligned(std::size_t bytes, std::size_t alignment);
/// Frees what allocate_aligned returned for the same `bytes` and `alignment`.
void deallocate_aligned(void* pointer, std::size_t bytes, std::size_t alignment) noexcept;
}  // namespace detail

/// An allocator that aligns a vector's storage to `kAlignment` bytes (cache lines), and large
/// vectors to huge pages (see detail::allocate_aligned).
template <class T, std::size_t kAlignment = 64>
struct AlignedAllocator {
    using value_type = T;
    template <class U>
    struct rebind {
        using other = AlignedAllocator<U, kAlignment>;
    };
    AlignedAllocator() = default;
    template <class U>
    AlignedAllocator(const AlignedAllocator<U, kAlignment>&) {}
    T* allocate(std::size_t n) {
        return static_cast<T*>(detail::allocate_aligned(n * sizeof(T), kAlignment));
    }
    void deallocate(T* p, std::size_t n) noexcept {
        detail::deallocate_aligned(p, n * sizeof(T), kAlignment);
    }
    /// Elements made without a value are default-initialised (left as they are, for the
    /// node and block types), so that resizing a large array does not first zero it.
    template <class U>
    void construct(U* p) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    template <class U>
    bool operator==(const AlignedAllocator<U, kAlignment>&) const {
        return true;
    }
};

/// Wide nodes as a Bvh stores them: cache-line aligned, huge pages when large.
template <int kWidth>
using WideBvhNodes = std::vector<WideBvhNode<kWidth>, AlignedAllocator<WideBvhNode<kWidth>>>;

/// The triangles of a Bvh's leaves as it stores them for TriangleSet<float> (see
/// BvhConfig::triangle_blocks). A leaf of n triangles owns 4 ceil(n / 4) lanes from lane
/// 4 first on (first: the leaf child's reference, see Bvh::binary_nodes), in groups of eight
/// lanes while more than four are left, then one of four. A group of W lanes is the 10 W floats
/// from lanes[10 l] (l: its first lane): nine rows of W, coordinate a of corner k of its lane j at
/// (3 k + a) W + j as the set stores it, so that the group's lanes of one coordinate load at
/// once (eight for one AVX2 step, four for SSE, as Embree's Triangle4 keeps four), then the W
/// triangle indices (their bits, std::bit_cast to float). Lanes past n hold zeros and kNoIndex
/// and are never tested. 40 bytes a lane.
struct BvhLeafTriangles {
    std::vector<float, AlignedAllocator<float>> lanes;

    /// Lane `lane` of the leaf (first, count): where its group starts in `lanes`, the group's
    /// width and the lane's place in it.
    struct Place {
        std::size_t group;
        std::size_t width;
        std::size_t lane;
    };
    static Place place(std::uint32_t first, std::uint32_t count, std::uint32_t lane) {
        const std::uint32_t start = lane / 8 * 8;
        return {10 * (4 * std::size_t{first} + start), count - start > 4 ? 8u : 4u,
                std::size_t{lane - start}};
    }
    float corner(const Place& at, int k, int axis) const {
        return lanes[at.group + std::size_t(3 * k + axis) * at.width + at.lane];
    }
    std::uint32_t primitive(const Place& at) const {
        return std::bit_cast<std::uint32_t>(lanes[at.group + 9 * at.width + at.lane]);
    }

    bool empty() const { return lanes.empty(); }
    std::size_t bytes() const { return lanes.capacity() * sizeof(float); }
};

namespace detail {

/// What the builder knows of a primitive: a conservative float box and the primitive's index
/// in its set; it bins the box centres, as Wald (2007) does. The builder never sees the set.
/// 32 bytes, so that each half loads as one SIMD register.
struct alignas(16) BuildPrimitive {
    float lower[3];
    std::uint32_t index;
    float upper[3];
    /// Zero (the fourth lane of the box's upper corner).
    float unused;
};

/// A binary BVH as built: nodes (see BvhNode), the primitive indices in leaf order, and
/// figures for the stats.
struct BinaryBvh {
    std::vector<BvhNode, AlignedAllocator<BvhNode>> nodes;
    std::vector<std::uint32_t> indices;
    /// Levels below the root of the deepest leaf (0 for a lone leaf).
    int depth = 0;
    std::size_t leaves = 0;
    /// The tree's SAH cost (expected cost of a random ray that hits the root box).
    double sah_cost = 0.0;
};

/// Builds a binary BVH over `primitives` (reordered in place) with the binned surface-area
/// heuristic of Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007.
/// A leaf of n primitives costs ceil(n / leaf_block) primitive tests (leaf_block, a power of
/// two: 4 for leaves tested four primitives at a time). Beyond a depth of kMaxSahDepth nodes are
/// split at the object median instead, so the depth stays under kMaxDepth whatever the input. A
/// leaf's `offset` is the position of its first primitive in `primitives` and `indices`; leaves
/// cover those positions in order, left subtrees first. The config is assumed valid.
BinaryBvh build_binary_bvh(std::span<BuildPrimitive> primitives, const BvhConfig& config,
                           int leaf_block = 1);

/// Collapses a binary BVH into kWidth-wide nodes ("convert, don't rebuild"): each wide node
/// takes the place of a binary node and adopts up to kWidth descendants, opening the child
/// with the largest surface area first. Leaves keep their offset and count. The root is node
/// 0; a node's interior children are consecutive, each followed (after its siblings) by its
/// own subtree, depth first. With `parallel` the top levels' subtrees are collapsed as parallel
/// tasks, each into the nodes the serial collapse gives it: the array is the same, bit for bit,
/// whatever the scheduling.
template <int kWidth>
WideBvhNodes<kWidth> collapse_to_wide(const BinaryBvh& binary, bool parallel);

/// Depth past which the builder stops using the SAH (a pathological input could otherwise
/// peel one primitive off per level), and the depth bound that guarantees with 2^32
/// primitives at most: traversal stacks are sized from it.
inline constexpr int kMaxSahDepth = 64;
inline constexpr int kMaxDepth = kMaxSahDepth + 33;

}  // namespace detail
}  // namespace csgrt
