#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/core/shape.h"

namespace csgrt {

/// A list of shapes with a structure over it: what a Compound is made of, and what a Scene
/// builds at commit over its objects. The members with a finite box sit in a ShapeSet under
/// an acceleration structure chosen through make_accelerator; members with an infinite box
/// (planes) are kept apart and tested on every ray; members with an empty box can never be hit
/// and are dropped, and so are exact repeats of an earlier member (exact_repeats: the same
/// shape object in the same place), which answer every ray as that member does and lose every
/// tie to it: a pile of 2^20 coincident copies costs one test, not 2^20. Hits carry `object` = the
/// member's index in the list given to the constructor, and at equal t the lower member index wins,
/// wherever the two members sit (the one tie rule of ShapeSet, extended to the unbounded members).
///
/// Built once, then const and thread-safe; the structure refers to the set, so a group never
/// moves or copies (owners hold it by value or by pointer).
class ShapeGroup {
public:
    /// Builds the structure called `accelerator` over the bounded members ("auto":
    /// choose_accelerator). `reason` says why it was chosen: choose_accelerator's sentence for
    /// "auto", `requested_reason` otherwise. Throws InvalidParameter for a null member or an
    /// unknown structure name.
    ShapeGroup(std::span<const std::shared_ptr<const Shape>> members, std::string_view accelerator,
               const AcceleratorConfig& config, std::string requested_reason = "requested");
    ShapeGroup(const ShapeGroup&) = delete;
    ShapeGroup& operator=(const ShapeGroup&) = delete;

    /// Nearest hit of any member in [t_min, t_max]; on success writes `record` (object = member
    /// index) and returns true.
    bool nearest(const Ray& ray, HitRecord& record, QueryScratch& scratch) const;
    /// The same, counting the structure's work and one primitive test per unbounded member.
    bool nearest_counted(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                         TraversalCounters& counters) const;
    /// Whether any member is hit in [t_min, t_max]; stops at the first.
    bool any(const Ray& ray, QueryScratch& scratch) const;
    /// Appends each member's nearest hit in [t_min, t_max], at most one a member, in no
    /// particular order; an exact repeat of an earlier member gives none.
    void all(const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch) const;
    /// The same for the bounded members only (through the structure).
    void all_bounded(const Ray& ray, std::vector<HitRecord>& hits, QueryScratch& scratch) const;

    /// The bounded members, in member order (exact repeats left out), and the member index of
    /// set member i.
    const ShapeSet& bounded() const { return set_; }
    std::uint32_t member_of(std::size_t i) const { return set_member_[i]; }
    /// The members with an infinite box, by member index, in increasing order.
    const std::vector<std::uint32_t>& unbounded() const { return unbounded_; }
    /// The join of the bounded members' boxes (empty when there are none).
    const Aabb& bounded_bounds() const { return bounds_; }

    /// The structure over the bounded members (built even when there are none), why it was
    /// chosen, and its figures.
    std::string_view accelerator_name() const { return structure_->name(); }
    const std::string& accelerator_reason() const { return reason_; }
    AcceleratorStats accelerator_stats() const { return structure_->stats(); }

private:
    template <bool kCount>
    bool nearest_impl(const Ray& ray, HitRecord& record, QueryScratch& scratch,
                      TraversalCounters& counters) const;

    ShapeSet set_;
    std::vector<std::uint32_t> set_member_;
    std::unique_ptr<Accelerator<ShapeSet>> structure_;
    std::vector<std::uint32_t> unbounded_;
    std::vector<std::shared_ptr<const Shape>> unbounded_shapes_;
    Aabb bounds_;
    std::string reason_;
};

/// For each of `members`, whether it repeats an earlier member exactly: the same shape object,
/// bare or under an Instance, with a transform equal entry for entry (+0 and -0 alike).
std::vector<bool> exact_repeats(std::span<const Shape* const> members);

}  // namespace csgrt
