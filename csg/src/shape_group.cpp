#include "csgrt/csg/shape_group.h"

#include <algorithm>
#include <array>
#include <functional>
#include <utility>

#include "csgrt/accel/factory.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/query_cost.h"

namespace csgrt {

namespace {

/// Where a member is: the shape under an Instance (or the member itself) and the instance's
/// matrix (zeros for a bare shape, which no Instance can have: its linear part is invertible).
struct Placement {
    const Shape* shape = nullptr;
    std::array<double, 12> matrix{};

    bool operator==(const Placement&) const = default;
};

/// A hash of the shape and the translation: equal placements hash alike; the linear part is
/// left to the comparison (copies of one shape differ in their translation).
std::size_t hash_of(const Placement& placement) {
    std::size_t hash = std::hash<const Shape*>()(placement.shape);
    for (std::size_t k = 9; k < 12; ++k) {
        // boost::hash_combine's mixing step.
        hash ^= std::hash<double>()(placement.matrix[k]) + 0x9e3779b97f4a7c15ull + (hash << 6) +
                (hash >> 2);
    }
    return hash;
}

Placement placement_of(const Shape* member) {
    Placement placement;
    const auto* instance = dynamic_cast<const Instance*>(member);
    if (instance == nullptr) {
        placement.shape = member;
        return placement;
    }
    placement.shape = &instance->shape();
    const Transform& transform = instance->world_from_object();
    for (int row = 0; row < 3; ++row) {
        for (int column = 0; column < 3; ++column) {
            // + 0.0 turns -0 into +0, so equal entries hash alike.
            placement.matrix[static_cast<std::size_t>(3 * row + column)] =
                transform.linear()(row, column) + 0.0;
        }
        placement.matrix[static_cast<std::size_t>(9 + row)] = transform.translation()[row] + 0.0;
    }
    return placement;
}

}  // namespace

std::vector<bool> exact_repeats(std::span<const Shape* const> members) {
    // Member indices sorted by hash, then placement, then index: equal placements end up side
    // by side with the first of them leading, in O(n log n) whatever the input (a hash set would
    // allocate per member, and runs of equal hashes would compare in pairs). Indices, not
    // placements, are moved: a scene commits 10^6 members.
    std::vector<Placement> placements(members.size());
    std::vector<std::size_t> hashes(members.size());
    std::vector<std::size_t> order;
    order.reserve(members.size());
    for (std::size_t i = 0; i < members.size(); ++i) {
        if (members[i] == nullptr) continue;
        placements[i] = placement_of(members[i]);
        hashes[i] = hash_of(placements[i]);
        order.push_back(i);
    }
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        if (hashes[a] != hashes[b]) return hashes[a] < hashes[b];
        const Placement& first = placements[a];
        const Placement& second = placements[b];
        if (first.shape != second.shape)
            return std::less<const Shape*>()(first.shape, second.shape);
        if (first.matrix != second.matrix) return first.matrix < second.matrix;
        return a < b;
    });
    std::vector<bool> repeats(members.size(), false);
    for (std::size_t k = 1; k < order.size(); ++k) {
        repeats[order[k]] = placements[order[k]] == placements[order[k - 1]];
    }
    return repeats;
}

ShapeGroup::ShapeGroup(std::span<const std::shared_ptr<const Shape>> members,
                       std::string_view accelerator, const AcceleratorConfig& config,
                       std::string requested_reason) {
    require(members.size() < kNoIndex, "ShapeGroup", "member count", "below 2^32 - 1",
            members.size());
    std::vector<std::shared_ptr<const Shape>> bounded;
    std::vector<const Shape*> pointers(members.size());
    for (std::size_t i = 0; i < members.size(); ++i) {
        // Tested before the message is built: a scene commits tens of thousands of members.
        if (members[i] == nullptr)
            require(false, "ShapeGroup", "member " + std::to_string(i), "a shape", "null");
        pointers[i] = members[i].get();
    }
    const std::vector<bool> repeats = exact_repeats(pointers);
    for (std::size_t i = 0; i < members.size(); ++i) {
        const Aabb box = members[i]->bounds();
        if (box.is_empty() || repeats[i]) continue;
        if (box.is_finite()) {
            bounded.push_back(members[i]);
            set_member_.push_back(static_cast<std::uint32_t>(i));
            bounds_.extend(box);
        } else {
            unbounded_.push_back(static_cast<std::uint32_t>(i));
            unbounded_shapes_.push_back(members[i]);
        }
    }
    set_ = ShapeSet(std::move(bounded));
    std::string name(accelerator);
    if (name == "auto") {
        name = choose_accelerator(set_.size(), reason_);
    } else {
        reason_ = std::move(requested_reason);
    }
    structure_ = make_accelerator(name, set_, config);
}

template <bool kCount>
bool ShapeGroup::nearest_impl(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                              TraversalCounters& counters) const {
    HitRecord best;
    bool found = kCount ? structure_->intersect_counted(ray, best, scratch, counters)
                        : structure_->intersect(ray, best, scratch);
    if (found) best.object = set_member_[best.object];
    // The structure visits the bounded members in no fixed order and the set breaks its ties
    // by set index, which follows member order; the unbounded members join by the same rule.
    for (std::size_t k = 0; k < unbounded_.size(); ++k) {
        const std::uint32_t index = unbounded_[k];
        Ray narrowed = ray;
        if (found) narrowed.t_max = best.t;
        HitRecord candidate;
        if constexpr (kCount) ++counters.primitives_tested;
        if constexpr (!kCount) count_primitive_test(scratch);
        if (!unbounded_shapes_[k]->nearest_hit(narrowed, candidate, scratch)) continue;
        if (found && !(candidate.t < best.t || (candidate.t == best.t && index < best.object)))
            continue;
        best = candidate;
        best.object = index;
        found = true;
    }
    if (found) record = best;
    return found;
}

bool ShapeGroup::nearest(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    TraversalCounters unused;
    return nearest_impl<false>(ray, record, scratch, unused);
}

bool ShapeGroup::nearest_counted(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                                 TraversalCounters& counters) const {
    return nearest_impl<true>(ray, record, scratch, counters);
}

bool ShapeGroup::any(const Ray& ray, QueryScratch& scratch) const {
    if (structure_->occluded(ray, scratch)) return true;
    for (const auto& shape : unbounded_shapes_) {
        count_primitive_test(scratch);
        if (shape->any_hit(ray, scratch)) return true;
    }
    return false;
}

void ShapeGroup::all_bounded(const Ray& ray, std::vector<HitRecord>& hits,
                             QueryScratch& scratch) const {
    const std::size_t first = hits.size();
    structure_->all_hits(ray, hits, scratch);
    for (std::size_t k = first; k < hits.size(); ++k) hits[k].object = set_member_[hits[k].object];
}

void ShapeGroup::all(const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch) const {
    all_bounded(ray, hits, scratch);
    for (std::size_t k = 0; k < unbounded_.size(); ++k) {
        HitRecord candidate;
        count_primitive_test(scratch);
        if (!unbounded_shapes_[k]->nearest_hit(ray, candidate, scratch)) continue;
        candidate.object = unbounded_[k];
        hits.push_back(candidate);
    }
}

}  // namespace csgrt
