// RayClassification's queries: the ray's cell (cached per thread), then its candidate clusters
// in order along the face axis, each searched as a small BVH (nearest, any and all hits).

#include "csgrt/accel/ray_classification.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "accelerator_base.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "ray_classification_node.h"

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
    if constexpr (kKind == QueryKind::kNearest) {
        return intersect_impl<kCounted>(ray, answer, scratch, counters);
    } else {
        if (set_ == nullptr || !is_valid(ray)) return false;
        const auto prepared = set_->prepare(ray, scratch);
        if constexpr (kKind == QueryKind::kAny) {
            return visit_candidates<kCounted>(ray, counters, [&](std::uint32_t index) {
                if constexpr (kCounted) ++counters.primitives_tested;
                return set_->occluded(index, prepared);
            });
        } else {
            const std::size_t before = answer.size();
            visit_candidates<kCounted>(ray, counters, [&](std::uint32_t index) {
                if constexpr (kCounted) ++counters.primitives_tested;
                HitRecord hit;
                hit.t = ray.t_max;
                if (set_->intersect(index, prepared, hit)) answer.push_back(hit);
                return false;
            });
            return answer.size() > before;
        }
    }
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
template <bool kCount, class Visit>
bool RayClassification<Set>::visit_candidates(const Ray& ray, TraversalCounters& counters,
                                              Visit&& visit) const {
    TraversalCounters local;
    const Search search = find_candidates(ray, local);
    if constexpr (kCount) {
        counters.nodes_visited += local.nodes_visited;
        counters.boxes_tested += local.boxes_tested;
    }
    if (search.far) {
        for (std::uint32_t index : bounded_) {
            if (visit(index)) return true;
        }
    }
    const double stop = stop_position(search.w_origin, search.w_speed, ray.t_max);
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    std::uint32_t stack[kStackSize];
    // A cell's clusters are disjoint subtrees, so each primitive is reached at most once.
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
                    if (visit(cluster_primitives_[j])) return true;
                }
                continue;
            }
            stack[top++] = node.offset;
            stack[top++] = node.offset + 1;
        }
    }
    for (std::uint32_t index : unbounded_) {
        if (visit(index)) return true;
    }
    return false;
}

// The members defined here, which the header's extern template leaves to this source.
template const RayClassification<TriangleSet<float>>::Node*
RayClassification<TriangleSet<float>>::locate(int, const double[5], bool, TraversalCounters&,
                                              double[5], double[5], bool&) const;
template RayClassification<TriangleSet<float>>::Search
RayClassification<TriangleSet<float>>::find_candidates(const Ray&, TraversalCounters&, bool) const;
template const RayClassification<TriangleSet<double>>::Node*
RayClassification<TriangleSet<double>>::locate(int, const double[5], bool, TraversalCounters&,
                                               double[5], double[5], bool&) const;
template RayClassification<TriangleSet<double>>::Search
RayClassification<TriangleSet<double>>::find_candidates(const Ray&, TraversalCounters&, bool) const;
template const RayClassification<ShapeSet>::Node* RayClassification<ShapeSet>::locate(
    int, const double[5], bool, TraversalCounters&, double[5], double[5], bool&) const;
template RayClassification<ShapeSet>::Search RayClassification<ShapeSet>::find_candidates(
    const Ray&, TraversalCounters&, bool) const;

}  // namespace csgrt

CSGRT_INSTANTIATE_ACCELERATOR_BASE(csgrt::RayClassification);
