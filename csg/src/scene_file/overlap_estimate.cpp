// The overlap limit: how many leaf shapes a ray may have to test at one point. A structure
// culls shapes whose boxes a ray misses, never shapes piled in one place, so 2^20 copies of a
// sphere a nanometre apart cost 2^20 tests on every ray that meets them (a render that never
// ends), although the expanded-leaf count is legal. Exact repeats cost one test (ShapeGroup
// drops them) and are counted once.

#include <algorithm>
#include <cmath>

#include "csgrt/core/instance.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/shape_group.h"
#include "limits.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

namespace {

/// Sample points per list: the centres of at most this many members' boxes, evenly strided.
/// Each is tested against every member, so a list of n members costs at most 64 n box tests.
constexpr std::size_t kOverlapSamples = 64;

/// Nested members do not pile up: a ray meets the enclosing one first and, once it has a hit
/// there, skips the box inside (the shells of an onion cost a test or two each). A box
/// encloses another when it is larger by this fraction of the inner box's diagonal on every
/// side.
constexpr double kEnclosingMargin = 0.01;

bool encloses(const Aabb& outer, const Aabb& inner, double margin) {
    return (outer.lower.array() <= inner.lower.array() - margin).all() &&
           (outer.upper.array() >= inner.upper.array() + margin).all();
}

}  // namespace

std::uint64_t overlapping_leaves(const Shape& shape, OverlapMemo& memo) {
    if (const auto* instance = dynamic_cast<const Instance*>(&shape)) {
        return overlapping_leaves(instance->shape(), memo);
    }
    const std::vector<const Shape*> children = shape.children();
    if (children.empty()) return 1;
    if (const auto found = memo.find(&shape); found != memo.end()) return found->second;
    // A compound is a ShapeGroup, which drops exact repeats; a boolean asks every operand.
    const bool drops_repeats = dynamic_cast<const Compound*>(&shape) != nullptr;
    const std::uint64_t leaves = overlapping_leaves(children, drops_repeats, memo).leaves;
    memo.emplace(&shape, leaves);
    return leaves;
}

Overlap overlapping_leaves(std::span<const Shape* const> members, bool drops_repeats,
                           OverlapMemo& memo) {
    std::vector<bool> repeats(members.size(), false);
    if (drops_repeats) repeats = exact_repeats(members);
    struct Member {
        Aabb box;
        std::uint64_t leaves;
        std::size_t index;
    };
    std::vector<Member> bounded;
    // Members without a finite box (planes) are tested on every ray.
    std::uint64_t everywhere = 0;
    Overlap worst;
    for (std::size_t i = 0; i < members.size(); ++i) {
        if (repeats[i]) continue;
        const Aabb box = members[i]->bounds();
        if (box.is_empty()) continue;
        const std::uint64_t leaves = overlapping_leaves(*members[i], memo);
        if (box.is_finite()) {
            bounded.push_back({box, leaves, i});
        } else {
            everywhere = saturating_add(everywhere, leaves);
            if (worst.leaves == 0) worst.member = i;
        }
        if (leaves > worst.leaves) worst = {leaves, i};
    }
    worst.leaves = std::max(worst.leaves, everywhere);
    const std::size_t stride = std::max<std::size_t>(1, bounded.size() / kOverlapSamples);
    for (std::size_t s = 0; s < bounded.size(); s += stride) {
        const Aabb& sample = bounded[s].box;
        const Point3 point = sample.center();
        const double margin = kEnclosingMargin * sample.diagonal().norm();
        std::uint64_t leaves = everywhere;
        for (const Member& member : bounded) {
            if (member.box.contains(point) && !encloses(member.box, sample, margin) &&
                !encloses(sample, member.box, margin)) {
                leaves = saturating_add(leaves, member.leaves);
            }
        }
        if (leaves > worst.leaves) worst = {leaves, bounded[s].index};
    }
    return worst;
}

std::uint64_t grid_overlap(const std::size_t counts[3], const Vector3& spacing, const Aabb& item) {
    // An item that can never be hit (a disjoint intersection) piles up nothing.
    if (item.is_empty()) return 1;
    std::uint64_t copies = 1;
    for (int axis = 0; axis < 3; ++axis) {
        // Zero spacing along an axis makes its copies exact repeats of one another.
        if (spacing[axis] == 0.0) continue;
        const double extent = item.upper[axis] - item.lower[axis];
        // Copies whose boxes meet one point along the axis: spacing apart, extent wide.
        const double along = std::isfinite(extent)
                                 ? std::floor(extent / std::abs(spacing[axis])) + 1
                                 : static_cast<double>(counts[axis]);
        copies *=
            static_cast<std::uint64_t>(std::clamp(along, 1.0, static_cast<double>(counts[axis])));
    }
    return copies;
}

std::string overlap_message(std::uint64_t leaves) {
    std::string message = "about ";
    message.append(leaves == std::numeric_limits<std::uint64_t>::max() ? "2^64"
                                                                       : std::to_string(leaves));
    message.append(" leaf shapes overlap at one point, and a ray there must test each of them ");
    message.append("(exact repeats count once); at most ");
    message.append(std::to_string(kMaxOverlappingLeaves));
    message.append(" may (docs/scene-format.md, Limits)");
    return message;
}

}  // namespace csgrt::detail::scene_file
