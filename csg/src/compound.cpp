#include "csgrt/csg/compound.h"

#include <algorithm>
#include <span>
#include <utility>

#include "csgrt/core/error.h"
#include "csgrt/csg/span_combine.h"

namespace csgrt {

namespace {

/// Up to this many bounded children, find_spans box-tests each child in turn; above it, it asks
/// the structure which children the ray's line meets.
constexpr std::size_t kLinearSpanChildren = 8;

bool box_hit(const Aabb& box, const Ray& ray, const Vector3& inverse_direction) {
    double t_enter, t_exit;
    return !box.is_empty() && box.intersect(ray, inverse_direction, t_enter, t_exit);
}

bool is_bounded(const Aabb& box) {
    return box.is_finite();
}

}  // namespace

std::string choose_accelerator(std::size_t count, std::string& reason) {
    if (count <= kHandfulOfMembers) {
        reason = std::to_string(count) + " bounded member" + (count == 1 ? "" : "s") +
                 " (at most " + std::to_string(kHandfulOfMembers) +
                 "): tested directly, no hierarchy";
        return "brute";
    }
    const auto names = accelerator_names();
    if (std::find(names.begin(), names.end(), "bvh") != names.end()) {
        reason = std::to_string(count) + " bounded members: a BVH over their boxes";
        return "bvh";
    }
    reason = std::to_string(count) +
             " bounded members: brute force, because this build has no BVH (\"bvh\" is not "
             "registered with make_accelerator)";
    return "brute";
}

Compound::Compound(std::vector<std::shared_ptr<const Shape>> children, const CompoundConfig& config)
    : children_(std::move(children)) {
    std::vector<std::shared_ptr<const Shape>> bounded;
    solid_ = !children_.empty();
    for (std::size_t i = 0; i < children_.size(); ++i) {
        const auto& child = children_[i];
        require(child != nullptr, "Compound", "child " + std::to_string(i), "a shape", "null");
        solid_ = solid_ && child->is_solid();
        const Aabb box = child->bounds();
        bounds_.extend(box);
        // A child with an empty box can never be hit; it is neither tested nor bounded.
        if (box.is_empty()) continue;
        if (is_bounded(box)) {
            bounded.push_back(child);
            set_child_.push_back(static_cast<std::uint32_t>(i));
        } else {
            unbounded_.push_back(static_cast<std::uint32_t>(i));
        }
    }
    set_ = ShapeSet(std::move(bounded));
    std::string name = config.accelerator;
    if (name == "auto") {
        name = choose_accelerator(set_.size(), accelerator_reason_);
    } else {
        accelerator_reason_ = "requested";
    }
    if (set_.size() > 0) structure_ = make_accelerator(name, set_, config.accelerator_config);
}

std::string_view Compound::accelerator_name() const {
    return structure_ ? structure_->name() : std::string_view();
}

AcceleratorStats Compound::accelerator_stats() const {
    return structure_ ? structure_->stats() : AcceleratorStats{};
}

bool Compound::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    if (unbounded_.empty() && !box_hit(bounds_, ray, inverse_direction)) return false;
    HitRecord best;
    bool found = structure_ && structure_->intersect(ray, best, scratch);
    if (found) best.object = set_child_[best.object];
    for (const std::uint32_t index : unbounded_) {
        Ray narrowed = ray;
        if (found) narrowed.t_max = best.t;
        HitRecord candidate;
        if (!children_[index]->nearest_hit(narrowed, candidate, scratch)) continue;
        // Children are visited in index order only within each group, so ties are decided here.
        if (found && !(candidate.t < best.t || (candidate.t == best.t && index < best.object)))
            continue;
        best = candidate;
        best.object = index;
        found = true;
    }
    if (found) record = best;
    return found;
}

bool Compound::any_hit(const Ray& ray, QueryScratch& scratch) const {
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    if (unbounded_.empty() && !box_hit(bounds_, ray, inverse_direction)) return false;
    if (structure_ && structure_->occluded(ray, scratch)) return true;
    for (const std::uint32_t index : unbounded_) {
        if (children_[index]->any_hit(ray, scratch)) return true;
    }
    return false;
}

void Compound::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    spans.clear();
    if (!solid_) return;
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    if (unbounded_.empty() && !box_hit(bounds_, ray, inverse_direction)) return;
    union_of_spans(ray, spans, scratch);
}

void Compound::union_of_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    // The candidates, as child indices in increasing order so that ties between children's
    // span ends always go to the lower index (combine_spans prefers its first operand).
    BorrowedHits candidates(scratch);
    std::vector<HitRecord>& list = candidates.list();
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    if (set_.size() <= kLinearSpanChildren) {
        for (std::size_t i = 0; i < set_.size(); ++i) {
            if (box_hit(set_.bounds(i), ray, inverse_direction)) {
                list.push_back(HitRecord{.object = set_child_[i]});
            }
        }
    } else if (structure_) {
        // A child whose spans overlap [t_min, t_max] enters at some finite t <= t_max, so its
        // line has a crossing in [-inf, t_max]; the structure finds those children without
        // visiting the others. (A child that wholly contains [t_min, t_max] has no crossing
        // inside it, which is why the interval is not used as it is.)
        Ray line = ray;
        line.t_min = -kInfinity;
        structure_->all_hits(line, list, scratch);
        for (HitRecord& hit : list) hit.object = set_child_[hit.object];
    }
    for (const std::uint32_t index : unbounded_) list.push_back(HitRecord{.object = index});
    std::sort(list.begin(), list.end(),
              [](const HitRecord& a, const HitRecord& b) { return a.object < b.object; });

    if (list.empty()) return;
    if (list.size() == 1) {
        children_[list.front().object]->find_spans(ray, spans, scratch);
        return;
    }
    BorrowedSpans child_spans(scratch);
    BorrowedSpans combined(scratch);
    children_[list.front().object]->find_spans(ray, spans, scratch);
    for (std::size_t k = 1; k < list.size(); ++k) {
        children_[list[k].object]->find_spans(ray, child_spans.list(), scratch);
        if (child_spans.list().empty()) continue;
        if (spans.empty()) {
            std::swap(spans, child_spans.list());
            continue;
        }
        combine_spans(BooleanOperation::Union, spans, child_spans.list(), ray, combined.list());
        std::swap(spans, combined.list());
    }
}

bool Compound::contains(const Point3& p) const {
    if (!solid_ || !bounds_.contains(p)) return false;
    return std::any_of(children_.begin(), children_.end(),
                       [&](const auto& child) { return child->contains(p); });
}

namespace {

using Shapes = std::vector<std::shared_ptr<const Shape>>;

std::shared_ptr<const Shape> group(std::span<std::shared_ptr<const Shape>> shapes,
                                   std::size_t max_children, const CompoundConfig& config) {
    if (shapes.size() == 1) return shapes.front();
    if (shapes.size() <= max_children) {
        return std::make_shared<Compound>(Shapes(shapes.begin(), shapes.end()), config);
    }
    Aabb centres;
    for (const auto& shape : shapes) centres.extend(shape->bounds().center());
    const int axis = centres.longest_axis();
    std::sort(shapes.begin(), shapes.end(), [axis](const auto& a, const auto& b) {
        return a->bounds().center()[axis] < b->bounds().center()[axis];
    });
    // max_children nearly equal runs along the axis, each grouped the same way.
    Shapes parts;
    std::size_t begin = 0;
    for (std::size_t part = 1; part <= max_children; ++part) {
        const std::size_t end = shapes.size() * part / max_children;
        if (end > begin)
            parts.push_back(group(shapes.subspan(begin, end - begin), max_children, config));
        begin = end;
    }
    return std::make_shared<Compound>(std::move(parts), config);
}

}  // namespace

std::shared_ptr<const Shape> make_hierarchy(std::vector<std::shared_ptr<const Shape>> shapes,
                                            std::size_t max_children,
                                            const CompoundConfig& config) {
    require(!shapes.empty(), "make_hierarchy", "shapes", "at least one shape", shapes.size());
    require(max_children >= 2, "make_hierarchy", "max_children", ">= 2", max_children);
    Shapes bounded;
    Shapes top;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
        require(shapes[i] != nullptr, "make_hierarchy", "shape " + std::to_string(i), "a shape",
                "null");
        (is_bounded(shapes[i]->bounds()) ? bounded : top).push_back(std::move(shapes[i]));
    }
    if (!bounded.empty()) top.push_back(group(bounded, max_children, config));
    if (top.size() == 1) return top.front();
    return std::make_shared<Compound>(std::move(top), config);
}

}  // namespace csgrt
