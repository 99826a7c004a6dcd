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

/// Nested members do not pile up: a ray meets the enclosing one first and, once it has a hit
/// there, skips the box inside (the shells of an onion cost a test or two each). A box
/// encloses another when it is larger by this fraction of the inner box's diagonal on every
/// side.
constexpr double kEnclosingMargin = 0.01;

bool encloses(const Aabb& outer, const Aabb& inner, double margin) {
    return (outer.lower.array() <= inner.lower.array() - margin).all() &&
           (outer.upper.array() >= inner.upper.array() + margin).all();
}

/// A member of a list with a finite box, as the estimate sees it.
struct Member {
    Aabb box;
    std::uint64_t leaves;
    std::size_t index;
};

/// One sample: the centre of a member's box, where the members it neither encloses nor is
/// enclosed by (with the margin) are counted.
struct Sample {
    Aabb box;
    Point3 point;
    double margin;

    explicit Sample(const Aabb& member)
        : box(member),
          point(member.center()),
          margin(kEnclosingMargin * member.diagonal().norm()) {}

    bool counts(const Aabb& other) const {
        return other.contains(point) && !encloses(other, box, margin) &&
               !encloses(box, other, margin);
    }
};

/// Members at most this many are counted at every sample one by one (n^2 box tests); longer
/// lists go through an OverlapTree, which gives the same sums.
constexpr std::size_t kDirectMembers = 32;

/// The members' boxes in a k-d tree over the six coordinates of each box (lower and upper
/// corner), split at the median of the coordinate that varies most: members side by side are
/// split by position, nested ones (shells with one centre) by size. Each node knows the union
/// and the common part of the boxes below it, so a sample takes a whole node at once when
/// every member in it counts there, or skips it when none can: a node whose union misses the
/// point, whose common part encloses the sample, or whose union the sample encloses. Sums are
/// exactly those of testing every member at the sample.
class OverlapTree {
public:
    explicit OverlapTree(std::vector<Member>& members) : members_(members) {
        nodes_.reserve(2 * (members.size() / kLeafMembers + 1));
        build(0, members.size());
    }

    /// The leaves of the members `sample` counts, saturating.
    std::uint64_t count(const Sample& sample) const { return count(0, sample); }

private:
    static constexpr std::size_t kLeafMembers = 8;

    struct Node {
        Aabb all;
        /// The intersection of the members' boxes (empty when they share no point).
        Aabb common;
        std::uint64_t leaves = 0;
        std::size_t begin = 0, end = 0;
        /// The children's indices; 0 (the root, never a child) for a leaf node.
        std::size_t first = 0, second = 0;
    };

    static double coordinate(const Aabb& box, int k) {
        return k < 3 ? box.lower[k] : box.upper[k - 3];
    }

    std::size_t build(std::size_t begin, std::size_t end) {
        const std::size_t at = nodes_.size();
        nodes_.emplace_back();
        Node node;
        node.begin = begin;
        node.end = end;
        node.common.lower = Point3::Constant(-kInfinity);
        node.common.upper = Point3::Constant(kInfinity);
        for (std::size_t i = begin; i < end; ++i) {
            const Aabb& box = members_[i].box;
            node.all.extend(box);
            node.common.lower = node.common.lower.cwiseMax(box.lower);
            node.common.upper = node.common.upper.cwiseMin(box.upper);
            node.leaves = saturating_add(node.leaves, members_[i].leaves);
        }
        if (end - begin > kLeafMembers) {
            // The lower corners range from the union's lower corner to the common part's, the
            // upper ones from the common part's upper corner to the union's.
            const auto spread = [&node](int k) {
                return k < 3 ? node.common.lower[k] - node.all.lower[k]
                             : node.all.upper[k - 3] - node.common.upper[k - 3];
            };
            int split = 0;
            for (int k = 1; k < 6; ++k) {
                if (spread(k) > spread(split)) split = k;
            }
            const std::size_t middle = begin + (end - begin) / 2;
            std::nth_element(members_.begin() + static_cast<std::ptrdiff_t>(begin),
                             members_.begin() + static_cast<std::ptrdiff_t>(middle),
                             members_.begin() + static_cast<std::ptrdiff_t>(end),
                             [split](const Member& a, const Member& b) {
                                 return coordinate(a.box, split) < coordinate(b.box, split);
                             });
            node.first = build(begin, middle);
            node.second = build(middle, end);
        }
        nodes_[at] = node;
        return at;
    }

    std::uint64_t count(std::size_t at, const Sample& sample) const {
        const Node& node = nodes_[at];
        if (!node.all.contains(sample.point) || encloses(node.common, sample.box, sample.margin) ||
            encloses(sample.box, node.all, sample.margin)) {
            return 0;
        }
        // Every member holds the point (each holds the common part), none encloses the sample
        // (each lies in the union) and the sample encloses none (each holds the common part).
        if (node.common.contains(sample.point) && !encloses(node.all, sample.box, sample.margin) &&
            !encloses(sample.box, node.common, sample.margin)) {
            return node.leaves;
        }
        if (node.first == 0) {
            std::uint64_t leaves = 0;
            for (std::size_t i = node.begin; i < node.end; ++i) {
                if (sample.counts(members_[i].box)) {
                    leaves = saturating_add(leaves, members_[i].leaves);
                }
            }
            return leaves;
        }
        return saturating_add(count(node.first, sample), count(node.second, sample));
    }

    std::vector<Member>& members_;
    std::vector<Node> nodes_;
};

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
    // Every member's centre is a sample, so a pile anywhere in a long list is found. The
    // samples are compared in the members' order, so the first member of the worst pile is
    // named.
    std::vector<std::uint64_t> at_member(members.size(), 0);
    std::vector<char> sampled(members.size(), 0);
    if (bounded.size() <= kDirectMembers) {
        for (const Member& at : bounded) {
            const Sample sample(at.box);
            for (const Member& member : bounded) {
                if (sample.counts(member.box)) {
                    at_member[at.index] = saturating_add(at_member[at.index], member.leaves);
                }
            }
            sampled[at.index] = 1;
        }
    } else {
        // The tree reorders `bounded`; each member keeps its index.
        const OverlapTree tree(bounded);
        for (const Member& at : bounded) {
            at_member[at.index] = tree.count(Sample(at.box));
            sampled[at.index] = 1;
        }
    }
    for (std::size_t i = 0; i < members.size(); ++i) {
        if (!sampled[i]) continue;
        const std::uint64_t leaves = saturating_add(everywhere, at_member[i]);
        if (leaves > worst.leaves) worst = {leaves, i};
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
