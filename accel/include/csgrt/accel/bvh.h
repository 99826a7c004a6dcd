#pragma once

#include <cstdint>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/bvh_build.h"

namespace csgrt {

namespace detail {
struct BoxRay;
}

/// A bounding volume hierarchy over a primitive set, built top down with the binned SAH
/// (Wald 2007, see bvh_build.h) and, by default, collapsed into 8-wide nodes whose boxes are
/// tested four at a time with SSE. Each primitive is referenced exactly once, by index, in
/// leaf order (a leaf of one primitive names it directly).
///
/// Boxes are float, rounded outward from the set's double boxes after padding them by
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
/// subtrees whose entry lies beyond the nearest hit so far are skipped.
template <class Set>
class Bvh final : public Accelerator<Set> {
public:
    /// Relative padding of primitive boxes and relative widening of slab intervals (2^-18,
    /// 64 float ulps: far above the few ulps the analysis needs, and too small to matter).
    static constexpr double kPrimitivePadding = 0x1p-18;
    static constexpr float kSlabSlack = 0x1p-18f;

    /// Throws InvalidParameter for a config outside the ranges documented in BvhConfig.
    void build(const Set& set, const BvhConfig& config = {});

    std::string_view name() const override { return "bvh"; }
    bool intersect(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool occluded(const Ray& ray, QueryScratch& scratch) const override;
    bool intersect_counted(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                           TraversalCounters& counters) const override;
    bool occluded_counted(const Ray& ray, QueryScratch& scratch,
                          TraversalCounters& counters) const override;
    void all_hits(const Ray& ray, std::vector<HitRecord>& hits,
                  QueryScratch& scratch) const override;
    AcceleratorStats stats() const override { return stats_; }

    /// The binary nodes (width 2), the 4- or 8-wide nodes (width 4 or 8; each empty for the
    /// other widths) and the primitive indices in leaf order: for tests of the tree's
    /// invariants.
    const std::vector<BvhNode, AlignedAllocator<BvhNode>>& binary_nodes() const {
        return binary_nodes_;
    }
    const std::vector<Bvh4Node>& nodes_4_wide() const { return nodes_4_; }
    const std::vector<Bvh8Node>& nodes_8_wide() const { return nodes_8_; }
    const std::vector<std::uint32_t>& primitive_indices() const { return indices_; }

private:
    /// Visits every leaf the ray may hit within [t_min, t_max], nearest entry first. `leaf`
    /// is called as leaf(primitives, count, t_max) with the leaf's primitive indices and the
    /// float upper bound of the interval, which it may lower; it returns true to stop.
    template <bool kCount, class LeafVisitor>
    void traverse(const Ray& ray, TraversalCounters& counters, LeafVisitor&& leaf) const;
    /// The traversal of each layout, for rays whose interval starts at t >= 0 (kSigned
    /// false) or may start below 0.
    template <bool kCount, bool kSigned, class LeafVisitor>
    void traverse_binary(const detail::BoxRay& box_ray, double t_max, TraversalCounters& counters,
                         LeafVisitor&& leaf) const;
    template <bool kCount, bool kSigned, int kWidth, class LeafVisitor>
    void traverse_wide(const std::vector<WideBvhNode<kWidth>>& nodes, const detail::BoxRay& box_ray,
                       double t_max, TraversalCounters& counters, LeafVisitor&& leaf) const;

    template <bool kCount>
    bool intersect_impl(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                        TraversalCounters& counters) const;
    template <bool kCount>
    bool occluded_impl(const Ray& ray, QueryScratch& scratch, TraversalCounters& counters) const;

    const Set* set_ = nullptr;
    BvhConfig config_;
    std::vector<BvhNode, AlignedAllocator<BvhNode>> binary_nodes_;
    std::vector<Bvh4Node> nodes_4_;
    std::vector<Bvh8Node> nodes_8_;
    std::vector<std::uint32_t> indices_;
    AcceleratorStats stats_;
};

class ShapeSet;
template <class Real>
class TriangleSet;
extern template class Bvh<TriangleSet<float>>;
extern template class Bvh<TriangleSet<double>>;
extern template class Bvh<ShapeSet>;

}  // namespace csgrt
