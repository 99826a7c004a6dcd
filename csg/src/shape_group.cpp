#include "csgrt/csg/shape_group.h"

#include <utility>

#include "csgrt/accel/factory.h"
#include "csgrt/core/error.h"

namespace csgrt {

ShapeGroup::ShapeGroup(std::span<const std::shared_ptr<const Shape>> members,
                       std::string_view accelerator, const AcceleratorConfig& config,
                       std::string requested_reason) {
    require(members.size() < kNoIndex, "ShapeGroup", "member count", "below 2^32 - 1",
            members.size());
    std::vector<std::shared_ptr<const Shape>> bounded;
    for (std::size_t i = 0; i < members.size(); ++i) {
        // Tested before the message is built: a scene commits tens of thousands of members.
        if (members[i] == nullptr)
            require(false, "ShapeGroup", "member " + std::to_string(i), "a shape", "null");
        const Aabb box = members[i]->bounds();
        if (box.is_empty()) continue;
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
        if (!unbounded_shapes_[k]->nearest_hit(ray, candidate, scratch)) continue;
        candidate.object = unbounded_[k];
        hits.push_back(candidate);
    }
}

}  // namespace csgrt
