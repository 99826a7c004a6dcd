#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string_view>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/accel/bvh_build.h"
#include "csgrt/core/aabb.h"

namespace csgrt {

namespace detail {

/// The face of the direction cube a direction points through, and its coordinates on it: the
/// dominant axis a = argmax |d_i| (ties go to the lower axis), the sign of d_a, and
/// u = d_b / |d_a|, v = d_c / |d_a| in [-1, 1], with b = a+1, c = a+2 (mod 3).
struct DirectionFace {
    int axis;
    bool negative;
    double u, v;
};
/// Assumes a non-zero direction.
DirectionFace direction_face(const Vector3& direction);

/// One hypercube of 5D ray space: rays from a point of `origin` with direction
/// (±e_a + u e_b + v e_c) on the face (axis, negative), (u, v) in the given rectangle.
struct RayCell {
    int axis = 0;
    bool negative = false;
    Aabb origin;
    double u_lower = -1.0, u_upper = 1.0;
    double v_lower = -1.0, v_upper = 1.0;
};

/// Conservative beam test: false only when no ray of `cell` meets `box` at a parameter
/// t >= 0. The beam {o + t dir} is the Minkowski sum of the origin box and the cone of
/// directions, a convex set; the test checks its projections: the t range in which a ray can
/// be inside the box's slab along the face axis, then the spread of the other two coordinates
/// over that t range (Arvo & Kirk, "Fast Ray Tracing by Ray Classification", SIGGRAPH 1987).
/// Exact arithmetic would make it conservative; in double it may miss a box by a few ulps of
/// the coordinates, which the structure's box padding covers.
class Beam {
public:
    explicit Beam(const RayCell& cell)
        : a_(cell.axis),
          b_((cell.axis + 1) % 3),
          c_((cell.axis + 2) % 3),
          negative_(cell.negative) {
        // On a negative face the face axis is mirrored, so rays always advance along +a.
        origin_lower_a_ = negative_ ? -cell.origin.upper[a_] : cell.origin.lower[a_];
        origin_upper_a_ = negative_ ? -cell.origin.lower[a_] : cell.origin.upper[a_];
        origin_lower_b_ = cell.origin.lower[b_];
        origin_upper_b_ = cell.origin.upper[b_];
        origin_lower_c_ = cell.origin.lower[c_];
        origin_upper_c_ = cell.origin.upper[c_];
        u_lower_ = cell.u_lower;
        u_upper_ = cell.u_upper;
        v_lower_ = cell.v_lower;
        v_upper_ = cell.v_upper;
    }

    /// The test for the box [lower, upper] (float or double corners).
    template <class Real>
    bool may_hit(const Real* lower, const Real* upper) const {
        const double box_lower_a = negative_ ? -double(upper[a_]) : double(lower[a_]);
        const double box_upper_a = negative_ ? -double(lower[a_]) : double(upper[a_]);
        // Along the face axis a ray advances by exactly t (its direction is e_a + ...), so
        // the parameters at which some ray is inside the box's slab form this interval.
        const double t_lower = std::max(box_lower_a - origin_upper_a_, 0.0);
        const double t_upper = box_upper_a - origin_lower_a_;
        if (!(t_lower <= t_upper)) return false;
        // Over that t range the other coordinates are o_k + t w, w in [w_lower, w_upper]:
        // the product is bilinear, so its extremes are at corners, and t >= 0 says which.
        const double low_b = origin_lower_b_ + (u_lower_ >= 0.0 ? t_lower : t_upper) * u_lower_;
        const double high_b = origin_upper_b_ + (u_upper_ >= 0.0 ? t_upper : t_lower) * u_upper_;
        const double low_c = origin_lower_c_ + (v_lower_ >= 0.0 ? t_lower : t_upper) * v_lower_;
        const double high_c = origin_upper_c_ + (v_upper_ >= 0.0 ? t_upper : t_lower) * v_upper_;
        return low_b <= double(upper[b_]) && high_b >= double(lower[b_]) &&
               low_c <= double(upper[c_]) && high_c >= double(lower[c_]);
    }

private:
    int a_, b_, c_;
    bool negative_;
    double origin_lower_a_, origin_upper_a_, origin_lower_b_, origin_upper_b_;
    double origin_lower_c_, origin_upper_c_;
    double u_lower_, u_upper_, v_lower_, v_upper_;
};

/// The beam test of `cell` for one box (see Beam).
inline bool beam_may_hit(const RayCell& cell, const Aabb& box) {
    return Beam(cell).may_hit(box.lower.data(), box.upper.data());
}

}  // namespace detail

/// Ray classification (Arvo & Kirk, "Fast Ray Tracing by Ray Classification", SIGGRAPH 1987):
/// a ray is a point of 5D ray space (where it enters the scene box, and its direction as a
/// point of one face of the direction cube), six binary trees of hypercubes cover that space,
/// and each hypercube keeps the candidates its beam can meet, sorted by where they begin along
/// the face's axis so a search stops at the first candidate beyond the best hit. Candidates
/// are clusters of primitives (nodes of a bounding-volume hierarchy), cut finer as the beams
/// narrow, so a wide beam lists a few large clusters rather than thousands of primitives.
/// Hypercubes are split lazily, when rays reach them; lazy splitting is thread-safe, and once
/// a path is built queries take no lock (docs/structures.md).
template <class Set>
class RayClassification final : public AcceleratorBase<RayClassification<Set>, Set> {
public:
    RayClassification();
    ~RayClassification() override;
    RayClassification(const RayClassification&) = delete;
    RayClassification& operator=(const RayClassification&) = delete;

    /// Pads the primitives' boxes, clusters them, makes the six root cells, then subdivides
    /// to config.build_depth. Throws InvalidParameter for a bad configuration.
    void build(const Set& set, const RayClassificationConfig& config = {});
    /// Classifies `rays` as queries would, splitting every cell they reach that is too long
    /// (without waiting for config.visits_before_split visits), so a benchmark can time the
    /// lazy build apart from the queries. Safe alongside queries.
    void prebuild(std::span<const Ray> rays);

    static constexpr std::string_view kName = "rayclass";
    /// Every query (the Accelerator overrides come from AcceleratorBase).
    template <QueryKind kKind, bool kCounted>
    bool query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
               TraversalCounters& counters) const;
    /// The current figures: they grow as rays split cells.
    AcceleratorStats stats() const override;

    /// Bytes of all candidate lists and cells now held (never above the cap, unless the six
    /// roots alone are).
    std::size_t candidate_bytes() const { return candidate_bytes_.load(std::memory_order_relaxed); }
    /// Splits refused, and cells left with their parent's list, because of
    /// max_candidate_bytes.
    std::size_t splits_refused() const { return splits_refused_.load(std::memory_order_relaxed); }
    /// The half-width added to every primitive box, in scene units.
    double box_padding() const { return padding_; }

private:
    /// A cluster in a cell's list, with where its box begins along the face's axis (in the
    /// coordinate that grows along the rays).
    struct Candidate {
        float key;
        std::uint32_t cluster;
    };
    struct Node;
    /// The candidates one ray must search: a cell's sorted list of clusters, or, for a ray
    /// too far from the scene for the padding to cover its rounding, every bounded primitive.
    struct Search {
        const Candidate* candidates = nullptr;
        std::uint32_t count = 0;
        bool far = false;
        /// The ray's coordinate along the face axis is w_origin + t * w_speed.
        double w_origin = 0.0;
        double w_speed = 0.0;
    };

    /// The candidates of `ray`; `eager` splits the cells on the way however few rays visited.
    Search find_candidates(const Ray& ray, TraversalCounters& counters, bool eager = false) const;
    /// The leaf of tree `face` holding the ray-space point `coordinates` (x, y, z, u, v),
    /// splitting the cells on the way that are too long and often enough visited (or all of
    /// them if `eager`); writes the leaf's cell and whether the leaf is final (never split).
    const Node* locate(int face, const double coordinates[5], bool eager,
                       TraversalCounters& counters, double lower[5], double upper[5],
                       bool& final_leaf) const;
    /// Gives `node` two children without lists (or closes it at the memory cap), unless
    /// another thread already has.
    void split(Node& node, int face, int depth, const double lower[5], const double upper[5]) const;
    /// Cuts `child`'s list (cell [lower, upper]) from `parent`'s, unless another thread
    /// already has.
    void materialize(const Node& parent, Node& child, int face, const double lower[5],
                     const double upper[5]) const;
    std::mutex& lock_of(const Node& node) const;
    void subdivide(Node& node, int face, int depth, double lower[5], double upper[5]);
    /// The widths across the rays (along b and c) of the beam of cell [lower, upper] of
    /// tree `face`, where it leaves the scene.
    void beam_widths(int face, const double lower[5], const double upper[5], double& width_b,
                     double& width_c) const;
    int split_axis(int face, int depth, const double lower[5], const double upper[5]) const;
    void root_cell(double lower[5], double upper[5]) const;
    bool is_final(const Node& node, int depth) const;
    /// The nearest hit: candidate clusters in order along the ray, nearer halves first, each
    /// box tested against the best hit so far.
    template <bool kCount>
    bool intersect_impl(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                        TraversalCounters& counters) const;
    /// Calls visit(primitive) for every primitive a ray may hit in [t_min, t_max], in no
    /// particular order (occlusion and every hit): the bounded ones when the ray is too far
    /// for the padding, the leaves of the candidate clusters whose boxes it enters, the
    /// unbounded ones. Stops when visit returns true, and then returns true.
    template <bool kCount, class Visit>
    bool visit_candidates(const Ray& ray, TraversalCounters& counters, Visit&& visit) const;

    const Set* set_ = nullptr;
    RayClassificationConfig config_;
    /// The clusters: a binary BVH over the padded primitive boxes (detail::BvhNode layout).
    std::vector<BvhNode, AlignedAllocator<BvhNode>> clusters_;
    /// Primitive indices in cluster order.
    std::vector<std::uint32_t> cluster_primitives_;
    /// Primitives under each cluster.
    std::vector<std::uint32_t> cluster_sizes_;
    /// The bounded primitives, for rays too far away for the padding.
    std::vector<std::uint32_t> bounded_;
    /// Primitives without a finite box (unbounded shapes): every ray tests them.
    std::vector<std::uint32_t> unbounded_;
    /// The union of the padded boxes, padded once more: the origin range of every root.
    Aabb scene_;
    double padding_ = 0.0;
    /// How far a hit reported by the set may lie outside its primitive's exact box, relative
    /// to |origin|_inf + the scene's largest coordinate.
    double hit_error_ = 0.0;
    double largest_coordinate_ = 0.0;
    std::unique_ptr<Node[]> roots_;
    /// Lazy splits lock one of these, chosen by the node's address.
    mutable std::array<std::mutex, 64> split_locks_;
    mutable std::atomic<std::size_t> candidate_bytes_{0};
    mutable std::atomic<std::size_t> references_{0};
    mutable std::atomic<std::size_t> nodes_{0};
    mutable std::atomic<std::size_t> splits_refused_{0};
    mutable std::atomic<std::int64_t> lazy_nanoseconds_{0};
    mutable std::atomic<int> deepest_{0};
    double build_milliseconds_ = 0.0;
    std::uint64_t build_id_ = 0;
};

extern template class RayClassification<TriangleSet<float>>;
extern template class RayClassification<TriangleSet<double>>;
extern template class RayClassification<ShapeSet>;

}  // namespace csgrt
