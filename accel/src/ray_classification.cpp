#include "csgrt/accel/ray_classification.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "accelerator_base.h"
#include "split_query.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"

namespace csgrt {

namespace detail {

DirectionFace direction_face(const Vector3& direction) {
    const int axis = max_dimension(direction);
    const double length = std::abs(direction[axis]);
    // Division (not a product with 1/length) keeps |u|, |v| <= 1 exactly: a correctly rounded
    // quotient of |x| <= |y| never exceeds 1.
    return {axis, direction[axis] < 0.0, direction[(axis + 1) % 3] / length,
            direction[(axis + 2) % 3] / length};
}

}  // namespace detail

namespace {

/// How far a hit the set reports may lie outside its primitive's exact box, as a fraction of
/// |origin|_inf + the scene's largest coordinate. Woop's float test rounds the origin, the
/// translated corners, the shear and the edge functions: about 10 units of 2^-24 of those
/// magnitudes in all (Woop, Benthin, Wald 2013, section 4; the tests measure at most 4);
/// 64 leaves a wide margin. A shape set's members may be float meshes too, so it gets the
/// same bound; analytic shapes are far more accurate.
template <class Set>
constexpr double kHitError = 64 * 0x1p-24;
template <>
constexpr double kHitError<TriangleSet<double>> = 64 * 0x1p-53;

/// The largest float not above `value`: candidate keys may only err toward the ray's start.
float round_down(double value) {
    if (value >= double(std::numeric_limits<float>::max()))
        return std::numeric_limits<float>::max();
    if (!(value >= -double(std::numeric_limits<float>::max()))) return -kInfinity;
    float rounded = static_cast<float>(value);
    if (double(rounded) > value)
        rounded = std::nextafter(rounded, -std::numeric_limits<float>::infinity());
    return rounded;
}

constexpr int kDirectionU = 3;
constexpr int kDirectionV = 4;

/// Entries of a cluster-traversal stack: a binary tree of depth D needs D + 1.
constexpr int kStackSize = detail::kMaxDepth + 2;

/// The slab test of a float cluster box in double, as conservative as Aabb::intersect (Ize,
/// "Robust BVH Ray Traversal", JCGT 2013): t_far is moved out by 2 gamma(3) |t_far|. Writes
/// where the ray enters the box (at least t_min).
inline bool hits_box(const BvhNode& box, const Point3& origin, const Vector3& inverse, double t_min,
                     double t_max, double& t_enter) {
    for (int axis = 0; axis < 3; ++axis) {
        double t_near = (double(box.lower[axis]) - origin[axis]) * inverse[axis];
        double t_far = (double(box.upper[axis]) - origin[axis]) * inverse[axis];
        if (t_near > t_far) std::swap(t_near, t_far);
        t_far *= t_far >= 0.0 ? 1.0 + 2.0 * gamma(3) : 1.0 - 2.0 * gamma(3);
        // Written so a NaN slab leaves the interval unchanged.
        t_min = t_near > t_min ? t_near : t_min;
        t_max = t_far < t_max ? t_far : t_max;
    }
    t_enter = t_min;
    return !(t_min > t_max);
}

inline bool hits_box(const BvhNode& box, const Point3& origin, const Vector3& inverse, double t_min,
                     double t_max) {
    double t_enter;
    return hits_box(box, origin, inverse, t_min, t_max, t_enter);
}

/// Where a cluster begins along face axis `axis` in the coordinate that grows along the
/// rays: x_a, or -x_a on a negative face (exact: float boxes, exact negation).
inline float begin_key(const BvhNode& box, int axis, bool negative) {
    return negative ? -box.upper[axis] : box.lower[axis];
}

/// Numbers every build of every RayClassification, so a thread's cached leaf can never be
/// mistaken for a leaf of another structure, or of a rebuilt one at the same address.
std::atomic<std::uint64_t> next_build_id{1};

/// The leaf this thread's previous ray ended in, with its cell: consecutive rays of a camera
/// often share it, and a final leaf never changes, so they may skip the descent. Per thread,
/// so nothing is shared (Arvo & Kirk's "caching").
struct LeafCache {
    std::uint64_t build_id = 0;
    int face = -1;
    double lower[5];
    double upper[5];
    const void* leaf = nullptr;
};
thread_local LeafCache leaf_cache;

}  // namespace

template <class Set>
struct RayClassification<Set>::Node {
    /// Two children, published with release once created; null for a leaf. A child's list
    /// is cut from this node's list when a ray first reaches it (`ready`).
    std::atomic<Node*> children{nullptr};
    /// The candidates, sorted by key; owned unless `borrowed` (then the parent's list). Never
    /// freed before the structure: a ray may still search a list while its cell is split.
    const Candidate* candidates = nullptr;
    std::uint32_t count = 0;
    /// Primitives under the candidates.
    std::uint32_t covered = 0;
    /// Rays that found this leaf too long but not yet visited often enough to split.
    std::atomic<std::uint32_t> visits{0};
    /// The axis (x, y, z, u, v) the cell was halved along; written before `children`.
    std::uint8_t axis = 0;
    /// Set with release once `candidates`, `count` and `covered` are final.
    std::atomic<bool> ready{false};
    /// Set when a split was refused (memory cap): the leaf is final.
    std::atomic<bool> closed{false};
    /// The list is the parent's, shared because the memory cap refused a copy.
    bool borrowed = false;

    ~Node() {
        if (!borrowed) delete[] candidates;
        delete[] children.load(std::memory_order_relaxed);
    }
};

template <class Set>
RayClassification<Set>::RayClassification() = default;

template <class Set>
RayClassification<Set>::~RayClassification() = default;

template <class Set>
void RayClassification<Set>::build(const Set& set, const RayClassificationConfig& config) {
    const char* what = "RayClassification";
    require(config.max_leaf_candidates >= 1, what, "max_leaf_candidates", ">= 1",
            config.max_leaf_candidates);
    require(config.max_depth >= 0 && config.max_depth <= 60, what, "max_depth", "in [0, 60]",
            config.max_depth);
    require(config.build_depth >= 0 && config.build_depth <= 60, what, "build_depth", "in [0, 60]",
            config.build_depth);
    require(config.visits_before_split >= 1, what, "visits_before_split", ">= 1",
            config.visits_before_split);
    require(config.cluster_width > 0.0 && std::isfinite(config.cluster_width), what,
            "cluster_width", "finite and > 0", config.cluster_width);
    const auto start = std::chrono::steady_clock::now();
    set_ = &set;
    config_ = config;
    build_id_ = next_build_id.fetch_add(1, std::memory_order_relaxed);
    roots_.reset();
    candidate_bytes_ = references_ = nodes_ = splits_refused_ = 0;
    lazy_nanoseconds_ = 0;
    deepest_ = 0;
    hit_error_ = kHitError<Set>;

    const std::size_t count = set.size();
    if (config_.max_depth == 0) {
        // Each of the five axes needs about log2(sqrt(n)) halvings before a beam is as narrow
        // as a primitive; 2.4 rather than 2.5 of log2 n measured best on the armadillo.
        const double depth = std::round(2.4 * std::log2(std::max<double>(count, 2)));
        config_.max_depth = static_cast<int>(std::clamp(depth, 12.0, 60.0));
    }
    std::vector<Aabb> boxes(count);
    clusters_.clear();
    cluster_primitives_.clear();
    cluster_sizes_.clear();
    bounded_.clear();
    unbounded_.clear();
    Aabb bounds;
    for (std::size_t i = 0; i < count; ++i) {
        const Aabb box = set.bounds(i);
        if (box.is_finite() && !box.is_empty()) {
            boxes[i] = box;
            bounds.extend(box);
            bounded_.push_back(static_cast<std::uint32_t>(i));
        } else {
            unbounded_.push_back(static_cast<std::uint32_t>(i));
        }
    }
    largest_coordinate_ = 0.0;
    padding_ = 0.0;
    if (!bounded_.empty()) {
        const double largest =
            std::max(bounds.lower.cwiseAbs().maxCoeff(), bounds.upper.cwiseAbs().maxCoeff());
        const double diagonal = bounds.diagonal().norm();
        // Twice the hit error of a ray from up to 16 scene diagonals away (the rest of the
        // classification rounds in double, far below this), and at least 2^-20 of the scene
        // so rays of double-precision sets may come from much farther.
        padding_ = std::max(2.0 * hit_error_ * (2.0 * largest + 16.0 * diagonal),
                            0x1p-20 * (largest + diagonal));
        padding_ = std::max(padding_, std::numeric_limits<double>::min());
        largest_coordinate_ = largest;
        if (!(largest + diagonal + 4.0 * padding_ < 1e37)) {
            // Coordinates near the float range leave no room for padded float boxes and keys:
            // every ray tests everything.
            unbounded_.insert(unbounded_.end(), bounded_.begin(), bounded_.end());
            std::sort(unbounded_.begin(), unbounded_.end());
            bounded_.clear();
        }
    }
    if (!bounded_.empty()) {
        const Vector3 pad = Vector3::Constant(padding_);
        std::vector<detail::BuildPrimitive> primitives(bounded_.size());
        for (std::size_t k = 0; k < bounded_.size(); ++k) {
            const Aabb& box = boxes[bounded_[k]];
            for (int axis = 0; axis < 3; ++axis) {
                primitives[k].lower[axis] = round_down(box.lower[axis] - pad[axis]);
                primitives[k].upper[axis] = -round_down(-(box.upper[axis] + pad[axis]));
            }
            primitives[k].index = bounded_[k];
        }
        // Clusters: a binned-SAH hierarchy over the padded boxes (its node boxes are unions of
        // float boxes, so they hold every padded box exactly).
        BvhConfig cluster_config;
        cluster_config.max_leaf_size = 2;
        cluster_config.width = 2;
        cluster_config.parallel = false;
        detail::BinaryBvh tree = detail::build_binary_bvh(primitives, cluster_config);
        clusters_ = std::move(tree.nodes);
        clusters_.shrink_to_fit();  // the builder leaves room for twice the primitives
        cluster_primitives_ = std::move(tree.indices);
        cluster_sizes_.assign(clusters_.size(), 0);
        auto size_of = [&](auto&& self, std::uint32_t id) -> std::uint32_t {
            const BvhNode& node = clusters_[id];
            cluster_sizes_[id] =
                node.is_leaf() ? node.count : self(self, node.offset) + self(self, node.offset + 1);
            return cluster_sizes_[id];
        };
        size_of(size_of, 0);
        scene_ = Aabb(bounds.lower - 2.0 * pad, bounds.upper + 2.0 * pad);
        roots_ = std::make_unique<Node[]>(6);
        for (int face = 0; face < 6; ++face) {
            Node& root = roots_[face];
            root.candidates =
                new Candidate[1]{{begin_key(clusters_[0], face / 2, face % 2 == 1), 0}};
            root.count = 1;
            root.covered = cluster_sizes_[0];
            root.ready.store(true, std::memory_order_relaxed);
        }
        nodes_ = 6;
        references_ = 6;
        candidate_bytes_ = 6 * (sizeof(Node) + sizeof(Candidate));
        for (int face = 0; face < 6 && config.build_depth > 0; ++face) {
            double lower[5], upper[5];
            root_cell(lower, upper);
            subdivide(roots_[face], face, 0, lower, upper);
        }
    }
    build_milliseconds_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
void RayClassification<Set>::root_cell(double lower[5], double upper[5]) const {
    for (int k = 0; k < 3; ++k) {
        lower[k] = scene_.lower[k];
        upper[k] = scene_.upper[k];
    }
    lower[kDirectionU] = lower[kDirectionV] = -1.0;
    upper[kDirectionU] = upper[kDirectionV] = 1.0;
}

template <class Set>
bool RayClassification<Set>::is_final(const Node& node, int depth) const {
    return node.covered <= config_.max_leaf_candidates || depth >= config_.max_depth ||
           node.closed.load(std::memory_order_relaxed);
}

template <class Set>
void RayClassification<Set>::subdivide(Node& node, int face, int depth, double lower[5],
                                       double upper[5]) {
    if (is_final(node, depth) || depth >= config_.build_depth) return;
    split(node, face, depth, lower, upper);
    Node* children = node.children.load(std::memory_order_acquire);
    if (children == nullptr) return;
    const int axis = node.axis;
    const double middle = 0.5 * lower[axis] + 0.5 * upper[axis];
    for (int side = 0; side < 2; ++side) {
        double child_lower[5], child_upper[5];
        std::copy(lower, lower + 5, child_lower);
        std::copy(upper, upper + 5, child_upper);
        (side == 0 ? child_upper : child_lower)[axis] = middle;
        materialize(node, children[side], face, child_lower, child_upper);
        subdivide(children[side], face, depth + 1, child_lower, child_upper);
    }
}

template <class Set>
void RayClassification<Set>::beam_widths(int face, const double lower[5], const double upper[5],
                                         double& width_b, double& width_c) const {
    const int a = face / 2, b = (a + 1) % 3, c = (a + 2) % 3;
    const bool negative = face % 2 == 1;
    // The beam's width across the rays, along b and c: the origin extent, plus the origin
    // extent along a seen obliquely (rays leave at slope up to |u| or |v|), plus the fan of
    // directions over the distance the rays can still travel through the scene.
    const double reach = negative ? upper[a] - scene_.lower[a] : scene_.upper[a] - lower[a];
    const double extent_a = upper[a] - lower[a];
    const double slope_u = std::max(std::abs(lower[kDirectionU]), std::abs(upper[kDirectionU]));
    const double slope_v = std::max(std::abs(lower[kDirectionV]), std::abs(upper[kDirectionV]));
    width_b = upper[b] - lower[b] + extent_a * slope_u +
              (upper[kDirectionU] - lower[kDirectionU]) * reach;
    width_c = upper[c] - lower[c] + extent_a * slope_v +
              (upper[kDirectionV] - lower[kDirectionV]) * reach;
}

template <class Set>
int RayClassification<Set>::split_axis(int face, int depth, const double lower[5],
                                       const double upper[5]) const {
    if (config_.split == RayClassificationSplit::kCycle) return depth % 5;
    const int a = face / 2, b = (a + 1) % 3, c = (a + 2) % 3;
    const bool negative = face % 2 == 1;
    double width_b, width_c;
    beam_widths(face, lower, upper, width_b, width_c);
    const double reach = negative ? upper[a] - scene_.lower[a] : scene_.upper[a] - lower[a];
    const double extent_a = upper[a] - lower[a];
    const double slope_u = std::max(std::abs(lower[kDirectionU]), std::abs(upper[kDirectionU]));
    const double slope_v = std::max(std::abs(lower[kDirectionV]), std::abs(upper[kDirectionV]));
    // Halving an axis removes half its term of the widths; pick the axis that shrinks the
    // beam's cross section (width_b * width_c) by the largest factor.
    const double inverse_b = width_b > 0.0 ? 1.0 / width_b : 0.0;
    const double inverse_c = width_c > 0.0 ? 1.0 / width_c : 0.0;
    double gains[5];
    gains[a] = extent_a * (slope_u * inverse_b + slope_v * inverse_c);
    gains[b] = (upper[b] - lower[b]) * inverse_b;
    gains[c] = (upper[c] - lower[c]) * inverse_c;
    gains[kDirectionU] = (upper[kDirectionU] - lower[kDirectionU]) * reach * inverse_b;
    gains[kDirectionV] = (upper[kDirectionV] - lower[kDirectionV]) * reach * inverse_c;
    return static_cast<int>(std::max_element(gains, gains + 5) - gains);
}

template <class Set>
std::mutex& RayClassification<Set>::lock_of(const Node& node) const {
    return split_locks_[(reinterpret_cast<std::uintptr_t>(&node) / sizeof(Node)) %
                        split_locks_.size()];
}

template <class Set>
void RayClassification<Set>::split(Node& node, int face, int depth, const double lower[5],
                                   const double upper[5]) const {
    std::lock_guard<std::mutex> lock(lock_of(node));
    if (node.children.load(std::memory_order_relaxed) != nullptr ||
        node.closed.load(std::memory_order_relaxed))
        return;
    const std::size_t bytes = 2 * sizeof(Node);
    if (candidate_bytes_.fetch_add(bytes, std::memory_order_relaxed) + bytes >
        config_.max_candidate_bytes) {
        candidate_bytes_.fetch_sub(bytes, std::memory_order_relaxed);
        node.closed.store(true, std::memory_order_relaxed);
        splits_refused_.fetch_add(1, std::memory_order_relaxed);
        return;
    }
    node.axis = static_cast<std::uint8_t>(split_axis(face, depth, lower, upper));
    // Release: a reader that sees the children sees the axis. Their lists come later.
    node.children.store(new Node[2], std::memory_order_release);
    nodes_.fetch_add(2, std::memory_order_relaxed);
    int deepest = deepest_.load(std::memory_order_relaxed);
    while (depth + 1 > deepest &&
           !deepest_.compare_exchange_weak(deepest, depth + 1, std::memory_order_relaxed)) {
    }
}

template <class Set>
void RayClassification<Set>::materialize(const Node& parent, Node& child, int face,
                                         const double lower[5], const double upper[5]) const {
    const auto start = std::chrono::steady_clock::now();
    // The parent's lock: both children are cut from the parent's list.
    std::lock_guard<std::mutex> lock(lock_of(parent));
    if (child.ready.load(std::memory_order_relaxed)) return;
    detail::RayCell cell;
    cell.axis = face / 2;
    cell.negative = face % 2 == 1;
    cell.origin.lower = Point3(lower[0], lower[1], lower[2]);
    cell.origin.upper = Point3(upper[0], upper[1], upper[2]);
    cell.u_lower = lower[kDirectionU];
    cell.u_upper = upper[kDirectionU];
    cell.v_lower = lower[kDirectionV];
    cell.v_upper = upper[kDirectionV];
    const detail::Beam beam(cell);
    const int a = cell.axis, b = (a + 1) % 3, c = (a + 2) % 3;
    double width_b, width_c;
    beam_widths(face, lower, upper, width_b, width_c);
    const double limit_b = config_.cluster_width * width_b;
    const double limit_c = config_.cluster_width * width_c;
    auto meets = [&](std::uint32_t id) {
        return beam.may_hit(clusters_[id].lower, clusters_[id].upper);
    };
    // A child's list is cut from its parent's, never from the whole scene: each cluster the
    // beam meets is kept, or replaced by its halves while it is wider than the beam (or when
    // the beam meets only one of them). Reused per thread, so only what is kept is allocated.
    static thread_local std::vector<Candidate> kept;
    static thread_local std::vector<std::uint32_t> pending;
    kept.clear();
    pending.clear();
    for (std::uint32_t k = 0; k < parent.count; ++k)
        pending.push_back(parent.candidates[k].cluster);
    std::uint32_t covered = 0;
    while (!pending.empty()) {
        const std::uint32_t id = pending.back();
        pending.pop_back();
        const BvhNode& node = clusters_[id];
        if (!meets(id)) continue;
        if (!node.is_leaf()) {
            const bool wide = double(node.upper[b]) - double(node.lower[b]) > limit_b ||
                              double(node.upper[c]) - double(node.lower[c]) > limit_c;
            const bool first = wide || meets(node.offset);
            const bool second = wide || meets(node.offset + 1);
            if (wide || first != second) {
                if (first) pending.push_back(node.offset);
                if (second) pending.push_back(node.offset + 1);
                continue;
            }
            if (!first) continue;
        }
        kept.push_back(Candidate{begin_key(node, a, cell.negative), id});
        covered += cluster_sizes_[id];
    }
    std::sort(kept.begin(), kept.end(), [](const Candidate& x, const Candidate& y) {
        return x.key < y.key || (x.key == y.key && x.cluster < y.cluster);
    });
    const std::size_t bytes = kept.size() * sizeof(Candidate);
    const std::size_t before = candidate_bytes_.fetch_add(bytes, std::memory_order_relaxed);
    if (before + bytes > config_.max_candidate_bytes) {
        // No room for a copy: keep using the parent's list, and split no further here.
        candidate_bytes_.fetch_sub(bytes, std::memory_order_relaxed);
        splits_refused_.fetch_add(1, std::memory_order_relaxed);
        child.candidates = parent.candidates;
        child.count = parent.count;
        child.covered = parent.covered;
        child.borrowed = true;
        child.closed.store(true, std::memory_order_relaxed);
    } else {
        Candidate* list = new Candidate[kept.size()];
        std::copy(kept.begin(), kept.end(), list);
        child.candidates = list;
        child.count = static_cast<std::uint32_t>(kept.size());
        child.covered = covered;
        references_.fetch_add(kept.size(), std::memory_order_relaxed);
    }
    // Release: a reader that sees `ready` sees the list.
    child.ready.store(true, std::memory_order_release);
    lazy_nanoseconds_.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                    std::chrono::steady_clock::now() - start)
                                    .count(),
                                std::memory_order_relaxed);
}

template <class Set>
const typename RayClassification<Set>::Node* RayClassification<Set>::locate(
    int face, const double coordinates[5], bool eager, TraversalCounters& counters, double lower[5],
    double upper[5], bool& final_leaf) const {
    Node* node = &roots_[face];
    root_cell(lower, upper);
    final_leaf = false;
    for (int depth = 0;; ++depth) {
        ++counters.nodes_visited;
        // Acquire pairs with the releases in split() and materialize(): once built, a path
        // costs no lock.
        Node* children = node->children.load(std::memory_order_acquire);
        if (children == nullptr) {
            if (is_final(*node, depth)) {
                final_leaf = true;
                return node;
            }
            // A cell is refined only for rays that come back: a cell that one incoherent ray
            // reaches is cheaper searched than cut.
            if (!eager && node->visits.fetch_add(1, std::memory_order_relaxed) + 1 <
                              config_.visits_before_split)
                return node;
            split(*node, face, depth, lower, upper);
            children = node->children.load(std::memory_order_acquire);
            if (children == nullptr) {  // the memory cap refused the split
                final_leaf = true;
                return node;
            }
        }
        const int axis = node->axis;
        const double middle = 0.5 * lower[axis] + 0.5 * upper[axis];
        const Node* parent = node;
        if (coordinates[axis] < middle) {
            upper[axis] = middle;
            node = &children[0];
        } else {
            lower[axis] = middle;
            node = &children[1];
        }
        if (!node->ready.load(std::memory_order_acquire))
            materialize(*parent, *node, face, lower, upper);
    }
}

template <class Set>
typename RayClassification<Set>::Search RayClassification<Set>::find_candidates(
    const Ray& ray, TraversalCounters& counters, bool eager) const {
    Search search;
    if (!roots_) return search;
    const detail::DirectionFace direction = detail::direction_face(ray.direction);
    const int face = 2 * direction.axis + (direction.negative ? 1 : 0);
    const double origin_size = ray.origin.cwiseAbs().maxCoeff();
    if (hit_error_ * (origin_size + largest_coordinate_) > 0.5 * padding_) {
        // The set's own rounding for a ray from this far may exceed the padding: test every
        // bounded primitive, without box tests.
        search.far = true;
        return search;
    }
    ++counters.boxes_tested;
    double t_enter, t_exit;
    if (!scene_.intersect(ray, ray.direction.cwiseInverse(), t_enter, t_exit)) return search;
    // Classify where the ray enters the scene box (or starts, if inside), clamped into the
    // root cell against rounding; the padding covers the difference.
    const Point3 entry =
        (ray.origin + t_enter * ray.direction).cwiseMax(scene_.lower).cwiseMin(scene_.upper);
    const double coordinates[5] = {entry.x(), entry.y(), entry.z(), direction.u, direction.v};
    // Any leaf whose closed cell holds the ray's point has every candidate the ray needs; a
    // final leaf is never split, so its cached cell stays valid as long as the build.
    LeafCache& cache = leaf_cache;
    bool cached = cache.build_id == build_id_ && cache.face == face;
    for (int k = 0; k < 5 && cached; ++k)
        cached = coordinates[k] >= cache.lower[k] && coordinates[k] <= cache.upper[k];
    const Node* leaf;
    if (cached) {
        leaf = static_cast<const Node*>(cache.leaf);
        ++counters.nodes_visited;
    } else {
        cache.build_id = 0;  // invalid until locate() has written a final leaf's cell
        bool final_leaf = false;
        leaf = locate(face, coordinates, eager, counters, cache.lower, cache.upper, final_leaf);
        if (final_leaf) {
            cache.build_id = build_id_;
            cache.face = face;
            cache.leaf = leaf;
        }
    }
    search.candidates = leaf->candidates;
    search.count = leaf->count;
    const double sign = direction.negative ? -1.0 : 1.0;
    search.w_origin = sign * ray.origin[direction.axis];
    search.w_speed = std::abs(ray.direction[direction.axis]);
    return search;
}

namespace {
/// An upper bound on the face-axis coordinate w_origin + t w_speed of the ray at t, rounded
/// up by the error of its two operations (NaN for t = -inf, which never stops a search).
inline double stop_position(double w_origin, double w_speed, double t) {
    const double travel = t * w_speed;
    return (w_origin + travel) + 4.0 * kUnitRoundoff * (std::abs(w_origin) + std::abs(travel));
}
}  // namespace

template <class Set>
template <QueryKind kKind, bool kCounted>
bool RayClassification<Set>::query(const Ray& ray, QueryAnswer<kKind>& answer,
                                   QueryScratch& scratch, TraversalCounters& counters) const {
    return detail::SplitQuery::query<kKind, kCounted>(*this, ray, answer, scratch, counters);
}

template <class Set>
template <bool kCount>
bool RayClassification<Set>::intersect_impl(const Ray& ray, HitRecord& record,
                                            QueryScratch& scratch,
                                            TraversalCounters& counters) const {
    if (set_ == nullptr || !is_valid(ray)) return false;
    TraversalCounters local;
    const Search search = find_candidates(ray, local);
    const auto prepared = set_->prepare(ray, scratch);
    HitRecord best;
    best.t = ray.t_max;
    bool found = false;
    std::size_t tested = 0, boxes = 0;
    if (search.far) {
        for (std::uint32_t index : bounded_) found |= set_->intersect(index, prepared, best);
        tested += bounded_.size();
    }
    double stop = stop_position(search.w_origin, search.w_speed, best.t);
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    // Clusters whose boxes the ray enters, with where it enters them.
    struct Entry {
        std::uint32_t cluster;
        double t_enter;
    };
    Entry stack[kStackSize];
    for (std::uint32_t k = 0; k < search.count; ++k) {
        const Candidate candidate = search.candidates[k];
        // Sorted by where they begin along the face axis: nothing further can beat `best`.
        if (candidate.key > stop) break;
        double t_enter;
        ++boxes;
        if (!hits_box(clusters_[candidate.cluster], ray.origin, inverse_direction, ray.t_min,
                      best.t, t_enter))
            continue;
        int top = 0;
        stack[top++] = Entry{candidate.cluster, t_enter};
        while (top > 0) {
            const Entry entry = stack[--top];
            // A hit found since the box was tested may lie before it (the same test as
            // testing the box again).
            if (entry.t_enter > best.t) continue;
            const BvhNode& node = clusters_[entry.cluster];
            if (node.is_leaf()) {
                for (std::uint32_t j = node.offset; j < node.offset + node.count; ++j) {
                    ++tested;
                    if (set_->intersect(cluster_primitives_[j], prepared, best)) {
                        found = true;
                        stop = stop_position(search.w_origin, search.w_speed, best.t);
                    }
                }
                continue;
            }
            // Both halves are tested together (siblings share a cache line); the one the ray
            // enters first is searched first.
            double t_first, t_second;
            boxes += 2;
            const bool first = hits_box(clusters_[node.offset], ray.origin, inverse_direction,
                                        ray.t_min, best.t, t_first);
            const bool second = hits_box(clusters_[node.offset + 1], ray.origin, inverse_direction,
                                         ray.t_min, best.t, t_second);
            const Entry near{node.offset, t_first}, far{node.offset + 1, t_second};
            if (first && second) {
                const bool swap = t_second < t_first;
                stack[top++] = swap ? near : far;
                stack[top++] = swap ? far : near;
            } else if (first) {
                stack[top++] = near;
            } else if (second) {
                stack[top++] = far;
            }
        }
    }
    for (std::uint32_t index : unbounded_) found |= set_->intersect(index, prepared, best);
    if constexpr (kCount) {
        counters.nodes_visited += local.nodes_visited;
        counters.boxes_tested += local.boxes_tested + boxes;
        counters.primitives_tested += tested + unbounded_.size();
    }
    if (found) record = best;
    return found;
}

template <class Set>
template <bool kCount>
bool RayClassification<Set>::occluded_impl(const Ray& ray, QueryScratch& scratch,
                                           TraversalCounters& counters) const {
    if (set_ == nullptr || !is_valid(ray)) return false;
    TraversalCounters local;
    const Search search = find_candidates(ray, local);
    if constexpr (kCount) {
        counters.nodes_visited += local.nodes_visited;
        counters.boxes_tested += local.boxes_tested;
    }
    const auto prepared = set_->prepare(ray, scratch);
    if (search.far) {
        for (std::uint32_t index : bounded_) {
            if constexpr (kCount) ++counters.primitives_tested;
            if (set_->occluded(index, prepared)) return true;
        }
    }
    const double stop = stop_position(search.w_origin, search.w_speed, ray.t_max);
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    std::uint32_t stack[kStackSize];
    for (std::uint32_t k = 0; k < search.count; ++k) {
        const Candidate candidate = search.candidates[k];
        if (candidate.key > stop) break;
        int top = 0;
        stack[top++] = candidate.cluster;
        while (top > 0) {
            const BvhNode& node = clusters_[stack[--top]];
            if constexpr (kCount) ++counters.boxes_tested;
            if (!hits_box(node, ray.origin, inverse_direction, ray.t_min, ray.t_max)) continue;
            if (node.is_leaf()) {
                for (std::uint32_t j = node.offset; j < node.offset + node.count; ++j) {
                    if constexpr (kCount) ++counters.primitives_tested;
                    if (set_->occluded(cluster_primitives_[j], prepared)) return true;
                }
                continue;
            }
            stack[top++] = node.offset;
            stack[top++] = node.offset + 1;
        }
    }
    for (std::uint32_t index : unbounded_) {
        if constexpr (kCount) ++counters.primitives_tested;
        if (set_->occluded(index, prepared)) return true;
    }
    return false;
}

template <class Set>
template <bool kCount>
void RayClassification<Set>::all_hits_impl(const Ray& ray, std::vector<HitRecord>& hits,
                                           QueryScratch& scratch,
                                           TraversalCounters& counters) const {
    if (set_ == nullptr || !is_valid(ray)) return;
    TraversalCounters local;
    const Search search = find_candidates(ray, local);
    if constexpr (kCount) {
        counters.nodes_visited += local.nodes_visited;
        counters.boxes_tested += local.boxes_tested;
    }
    const auto prepared = set_->prepare(ray, scratch);
    auto collect = [&](std::uint32_t index) {
        if constexpr (kCount) ++counters.primitives_tested;
        HitRecord hit;
        hit.t = ray.t_max;
        if (set_->intersect(index, prepared, hit)) hits.push_back(hit);
    };
    if (search.far)
        for (std::uint32_t index : bounded_) collect(index);
    const double stop = stop_position(search.w_origin, search.w_speed, ray.t_max);
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    std::uint32_t stack[kStackSize];
    // A cell's clusters are disjoint subtrees, so each primitive is reported at most once.
    for (std::uint32_t k = 0; k < search.count && !(search.candidates[k].key > stop); ++k) {
        int top = 0;
        stack[top++] = search.candidates[k].cluster;
        while (top > 0) {
            const BvhNode& node = clusters_[stack[--top]];
            if constexpr (kCount) ++counters.boxes_tested;
            if (!hits_box(node, ray.origin, inverse_direction, ray.t_min, ray.t_max)) continue;
            if (node.is_leaf()) {
                for (std::uint32_t j = node.offset; j < node.offset + node.count; ++j)
                    collect(cluster_primitives_[j]);
                continue;
            }
            stack[top++] = node.offset;
            stack[top++] = node.offset + 1;
        }
    }
    for (std::uint32_t index : unbounded_) collect(index);
}

template <class Set>
void RayClassification<Set>::prebuild(std::span<const Ray> rays) {
    TraversalCounters unused;
    for (const Ray& ray : rays)
        if (set_ != nullptr && is_valid(ray)) find_candidates(ray, unused, true);
}

template <class Set>
AcceleratorStats RayClassification<Set>::stats() const {
    AcceleratorStats stats;
    stats.name = "rayclass";
    stats.build_milliseconds = build_milliseconds_;
    const std::size_t nodes = nodes_.load(std::memory_order_relaxed);
    const std::size_t candidate_bytes = candidate_bytes_.load(std::memory_order_relaxed);
    stats.bytes = clusters_.capacity() * sizeof(BvhNode) +
                  (cluster_primitives_.capacity() + cluster_sizes_.capacity() +
                   bounded_.capacity() + unbounded_.capacity()) *
                      sizeof(std::uint32_t) +
                  candidate_bytes;
    stats.nodes = nodes;
    stats.references = references_.load(std::memory_order_relaxed);
    stats.primitives = set_ != nullptr ? set_->size() : 0;
    const std::size_t refused = splits_refused_.load(std::memory_order_relaxed);
    const std::string cap_note =
        refused > 0 ? ", cap reached: " + std::to_string(refused) + " splits refused" : "";
    char details[400];
    std::snprintf(
        details, sizeof details,
        "leaf <= %u primitives, max depth %d (deepest %d), split %s after %u visits, "
        "%zu clusters (width %.2g), lazy splits %.1f ms, lists and cells %.1f MiB of cap "
        "%.1f MiB%s, padding %.3g, unbounded %zu",
        config_.max_leaf_candidates, config_.max_depth, deepest_.load(std::memory_order_relaxed),
        config_.split == RayClassificationSplit::kCycle ? "cycle" : "narrow-beam",
        config_.visits_before_split, clusters_.size(), config_.cluster_width,
        lazy_nanoseconds_.load(std::memory_order_relaxed) * 1e-6, candidate_bytes / 1048576.0,
        config_.max_candidate_bytes / 1048576.0, cap_note.c_str(), padding_, unbounded_.size());
    stats.details = details;
    return stats;
}

template class RayClassification<TriangleSet<float>>;
template class RayClassification<TriangleSet<double>>;
template class RayClassification<ShapeSet>;
template class AcceleratorBase<RayClassification<TriangleSet<float>>, TriangleSet<float>>;
template class AcceleratorBase<RayClassification<TriangleSet<double>>, TriangleSet<double>>;
template class AcceleratorBase<RayClassification<ShapeSet>, ShapeSet>;

}  // namespace csgrt
