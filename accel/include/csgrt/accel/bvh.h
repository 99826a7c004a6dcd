#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/bvh_build.h"

namespace csgrt {

namespace detail {
template <class Set>
struct BvhTraversal;
}

/// A bounding volume hierarchy over a primitive set, built top down with the binned SAH
/// (Wald 2007, see bvh_build.h) and, by default, collapsed into 8-wide nodes whose boxes are
/// tested eight at a time with AVX2 where the CPU has it, else four at a time with SSE. Each
/// primitive is referenced exactly once, in leaf order.
///
/// Boxes are float, rounded outward from the primitives' boxes after padding them by at least
/// kPrimitivePadding of their size and magnitude, and the float slab test widens each
/// [t_enter, t_exit] by the relative kSlabSlack (Ize, "Robust BVH Ray Traversal", JCGT 2013,
/// does this with 2 gamma(3) for the box test alone). Together they cover the rounding of the
/// box test (a few float ulps of t), the float ray origin, and the float triangle test, whose
/// hits lie a few float ulps of the triangle's size and coordinates off the exact triangle
/// (Woop et al. 2013): a primitive the set reports as hit is never culled, so every query
/// returns exactly what BruteForce returns. Rays the float test cannot represent (an origin
/// coordinate beyond 2^100, a non-zero direction component outside [2^-100, 2^100]) fall back
/// to visiting every node, which is slow but exact. docs/structures.md has the argument.
///
/// Traversal is near child first (by entry distance), with a fixed stack on the C++ stack;
/// subtrees whose entry lies beyond the nearest hit so far are skipped. For TriangleSet<float>
/// the leaves hold their triangles as structure of arrays in lanes of four
/// (BvhConfig::triangle_blocks, BvhLeafTriangles), tested four or eight at a time with SIMD lane
/// by lane in exactly the set's float arithmetic, so the answers stay the set's own.
template <class Set>
class Bvh final : public AcceleratorBase<Bvh<Set>, Set> {
public:
    /// Relative padding of primitive boxes and relative widening of slab intervals (2^-18,
    /// 64 float ulps: far above the few ulps the analysis needs, and too small to matter).
    static constexpr double kPrimitivePadding = 0x1p-18;
    static constexpr float kSlabSlack = 0x1p-18f;

    /// Throws InvalidParameter for a config outside the ranges documented in BvhConfig.
    void build(const Set& set, const BvhConfig& config = {});

    static constexpr std::string_view kName = "bvh";
    /// Every query (the Accelerator overrides come from AcceleratorBase).
    template <QueryKind kKind, bool kCounted>
    bool query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
               TraversalCounters& counters) const;

    /// Rays that intersect_packets and occluded_packets take through the tree together.
    static constexpr std::size_t kPacketRays = 8;
    /// The nearest hits of many rays, traced kPacketRays at a time through the tree together:
    /// each node is fetched once for the rays that enter it, which pays for coherent rays
    /// (camera rays of neighbouring pixels). hit[i] and, where it is true, records[i] are what
    /// intersect(rays[i], records[i], scratch) gives, bit for bit; records[i] of a miss is left
    /// as it was. Returns the number of hits. Width 2 and ShapeSet trees take one ray at a time.
    /// Throws InvalidParameter when the spans' sizes differ.
    std::size_t intersect_packets(std::span<const Ray> rays, std::span<HitRecord> records,
                                  std::span<bool> hit, QueryScratch& scratch) const;
    /// occluded(rays[i], scratch) into occluded[i], kPacketRays rays at a time as
    /// intersect_packets; returns the number of occluded rays.
    std::size_t occluded_packets(std::span<const Ray> rays, std::span<bool> occluded,
                                 QueryScratch& scratch) const;

    /// The binary nodes (width 2), the 4- or 8-wide nodes (width 4 or 8; each empty for the
    /// other widths), and the leaves' contents: primitive indices in leaf order, or the leaves'
    /// triangles (TriangleSet<float> with triangle_blocks; the indices are then empty). A leaf
    /// child (offset or first, count) names `count` primitives: with leaf triangles, the lanes
    /// from 4 first on (see BvhLeafTriangles); else the primitive `first` itself when count is
    /// 1 (saving a dependent load), or index entries first .. first + count - 1. For tests of
    /// the tree's invariants.
    const std::vector<BvhNode, AlignedAllocator<BvhNode>>& binary_nodes() const {
        return binary_nodes_;
    }
    const WideBvhNodes<4>& nodes_4_wide() const { return nodes_4_; }
    const WideBvhNodes<8>& nodes_8_wide() const { return nodes_8_; }
    const std::vector<std::uint32_t>& primitive_indices() const { return indices_; }
    const BvhLeafTriangles& leaf_triangles() const { return leaf_triangles_; }
    /// Whether queries run the AVX2 node test (BvhConfig::avx2 and a CPU that has AVX2 and FMA).
    bool uses_avx2() const { return use_avx2_; }

private:
    friend struct detail::BvhTraversal<Set>;
    using AcceleratorBase<Bvh<Set>, Set>::stats_;

    template <bool kAny>
    std::size_t trace_packets(std::span<const Ray> rays, std::span<HitRecord> records,
                              std::span<bool> hit, QueryScratch& scratch) const;

    /// Copies the triangles of each leaf of `tree` into leaf_triangles_, in leaf order, and
    /// points the leaves at their first lane group (TriangleSet<float> only).
    void fill_leaf_triangles(const Set& set, detail::BinaryBvh& tree, bool parallel);

    const Set* set_ = nullptr;
    BvhConfig config_;
    bool use_avx2_ = false;
    std::vector<BvhNode, AlignedAllocator<BvhNode>> binary_nodes_;
    WideBvhNodes<4> nodes_4_;
    WideBvhNodes<8> nodes_8_;
    std::vector<std::uint32_t> indices_;
    BvhLeafTriangles leaf_triangles_;
};

class ShapeSet;
template <class Real>
class TriangleSet;
extern template class Bvh<TriangleSet<float>>;
extern template class Bvh<TriangleSet<double>>;
extern template class Bvh<ShapeSet>;

}  // namespace csgrt
