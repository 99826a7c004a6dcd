#include "csgrt/csg/compound.h"

#include <algorithm>
#include <span>
#include <utility>

#include "csgrt/core/error.h"
#include "csgrt/core/query_cost.h"
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

std::vector<std::shared_ptr<const Shape>> checked_children(
    std::vector<std::shared_ptr<const Shape>> children) {
    for (std::size_t i = 0; i < children.size(); ++i) {
        require(children[i] != nullptr, "Compound", "child " + std::to_string(i), "a shape",
                "null");
    }
    return children;
}

}  // namespace

Compound::Compound(std::vector<std::shared_ptr<const Shape>> children, const CompoundConfig& config)
    : children_(checked_children(std::move(children))), config_(config) {
    if (!config.build_at_commit) build_group(config.accelerator, config.accelerator_config);
    solid_ = !children_.empty();
    for (const auto& child : children_) {
        solid_ = solid_ && child->is_solid();
        bounds_.extend(child->bounds());
    }
    coincidence_ = span_coincidence_relative(children_);
}

const ShapeGroup& Compound::build_group(std::string_view accelerator,
                                        const AcceleratorConfig& config) const {
    const std::lock_guard<std::mutex> lock(build_mutex_);
    if (owned_group_ == nullptr) {
        owned_group_ = std::make_unique<const ShapeGroup>(children_, accelerator, config);
        group_.store(owned_group_.get(), std::memory_order_release);
    }
    return *owned_group_;
}

void Compound::build_at_commit(std::string_view accelerator,
                               const AcceleratorConfig& config) const {
    if (is_built()) return;
    build_group(config_.accelerator == "auto" ? accelerator : std::string_view(config_.accelerator),
                config);
}

std::string_view Compound::accelerator_name() const {
    const ShapeGroup& members = group();
    return members.bounded().size() > 0 ? members.accelerator_name() : std::string_view();
}

AcceleratorStats Compound::accelerator_stats() const {
    const ShapeGroup& members = group();
    return members.bounded().size() > 0 ? members.accelerator_stats() : AcceleratorStats{};
}

bool Compound::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    const ShapeGroup& members = group();
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    if (members.unbounded().empty()) count_box_tests(scratch, 1);
    if (members.unbounded().empty() && !box_hit(bounds_, ray, inverse_direction)) return false;
    return members.nearest(ray, record, scratch);
}

bool Compound::any_hit(const Ray& ray, QueryScratch& scratch) const {
    const ShapeGroup& members = group();
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    if (members.unbounded().empty()) count_box_tests(scratch, 1);
    if (members.unbounded().empty() && !box_hit(bounds_, ray, inverse_direction)) return false;
    return members.any(ray, scratch);
}

void Compound::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    spans.clear();
    if (!solid_) return;
    const ShapeGroup& members = group();
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    if (members.unbounded().empty()) count_box_tests(scratch, 1);
    if (members.unbounded().empty() && !box_hit(bounds_, ray, inverse_direction)) return;
    union_of_spans(ray, spans, scratch);
}

void Compound::union_of_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    // The candidates, as child indices in increasing order so that ties between children's
    // span ends always go to the lower index (combine_spans prefers its first operand).
    BorrowedHits candidates(scratch);
    std::vector<HitRecord>& list = candidates.list();
    const ShapeGroup& members = group();
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    const ShapeSet& bounded = members.bounded();
    if (bounded.size() <= kLinearSpanChildren) {
        count_box_tests(scratch, bounded.size());
        for (std::size_t i = 0; i < bounded.size(); ++i) {
            if (box_hit(bounded.bounds(i), ray, inverse_direction)) {
                list.push_back(HitRecord{.object = members.member_of(i)});
            }
        }
    } else {
        // A child whose spans overlap [t_min, t_max] enters at some finite t <= t_max, so its
        // line has a crossing in [-inf, t_max]; the structure finds those children without
        // visiting the others. (A child that wholly contains [t_min, t_max] has no crossing
        // inside it, which is why the interval is not used as it is.)
        Ray line = ray;
        line.t_min = -kInfinity;
        members.all_bounded(line, list, scratch);
    }
    for (const std::uint32_t index : members.unbounded())
        list.push_back(HitRecord{.object = index});
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
        combine_spans(BooleanOperation::Union, spans, child_spans.list(), ray, combined.list(),
                      coincidence_);
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
