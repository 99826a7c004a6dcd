// RayClassification's build (clusters over the padded boxes, the six root cells) and the
// splitting of its cells, eager to build_depth and lazy below; the queries are
// ray_classification_query.cpp.

#include "csgrt/accel/ray_classification.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"
#include "ray_classification_node.h"

namespace csgrt {

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

using detail::kDirectionU;
using detail::kDirectionV;

/// Where a cluster begins along face axis `axis` in the coordinate that grows along the
/// rays: x_a, or -x_a on a negative face (exact: float boxes, exact negation).
inline float begin_key(const BvhNode& box, int axis, bool negative) {
    return negative ? -box.upper[axis] : box.lower[axis];
}

/// Numbers every build of every RayClassification, so a thread's cached leaf can never be
/// mistaken for a leaf of another structure, or of a rebuilt one at the same address.
std::atomic<std::uint64_t> next_build_id{1};

}  // namespace
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

}  // namespace csgrt
