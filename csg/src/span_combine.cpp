#include "csgrt/csg/span_combine.h"

#include <cmath>
#include <cstddef>
#include <unordered_set>
#include <utility>
#include <vector>

#include "csgrt/mesh/mesh.h"

namespace csgrt {

namespace {

// Ends are rounded like the coordinates of the points they name, |o| + |t d|, divided by |d|
// to turn a distance into t (max norms: no square roots, within sqrt(3) of the 2-norm).
double origin_over_direction(const Ray& ray) {
    return ray.origin.cwiseAbs().maxCoeff() / ray.direction.cwiseAbs().maxCoeff();
}

double coincidence_tolerance(double relative, double origin_over_direction, double t) {
    if (!std::isfinite(t)) return 0.0;
    return relative * (std::abs(t) + origin_over_direction);
}

/// Whether a float Mesh lies anywhere beneath any of `roots`; each shared shape is visited
/// once, so a grid of copies of one definition costs one walk of it.
bool holds_float_mesh(std::vector<const Shape*> pending) {
    std::unordered_set<const Shape*> seen;
    while (!pending.empty()) {
        const Shape* shape = pending.back();
        pending.pop_back();
        if (shape == nullptr || !seen.insert(shape).second) continue;
        if (const auto* mesh = dynamic_cast<const Mesh*>(shape)) {
            if (!mesh->double_precision()) return true;
            continue;
        }
        for (const Shape* child : shape->children()) pending.push_back(child);
    }
    return false;
}

/// What one operand does within a group of ends that count as coincident.
struct OperandStep {
    bool before = false;   // inside just before the group
    bool after = false;    // inside just after it
    bool touched = false;  // one of its ends lies in the group: its closed set meets it
    const HitRecord* entered = nullptr;  // the end it enters through (when !before && after)
    const HitRecord* exited = nullptr;   // the end it leaves through (when before && !after)
    const Span* point = nullptr;         // a span that began and ended within the group
};

/// Walks one operand's span ends in order: enter of span 0, exit of span 0, enter of span 1...
class Cursor {
public:
    explicit Cursor(const SpanList& spans) : spans_(spans), end_(2 * spans.size()) {}

    bool done() const { return next_ == end_; }
    double next_t() const { return done() ? kInfinity : end(next_).t; }

    /// The state when the operand has no end in the group.
    OperandStep stay() const {
        OperandStep step;
        step.before = step.after = inside_;
        return step;
    }

    /// Consumes every end with t <= limit, and at least one so that NaN ends cannot stall
    /// the sweep.
    OperandStep advance(double limit) {
        OperandStep step = stay();
        if (done()) return step;
        step.touched = true;
        const std::size_t first = next_;
        do {
            const Span& span = spans_[next_ / 2];
            if (next_ % 2 == 0) {
                inside_ = true;
            } else {
                if (next_ == first) step.exited = &span.exit;
                // Its enter was consumed in this group too: a touching point.
                if (next_ - 1 >= first && step.point == nullptr) step.point = &span;
                inside_ = false;
            }
            ++next_;
        } while (!done() && end(next_).t <= limit);
        step.after = inside_;
        // Inside now means the last end consumed was an enter.
        if (!step.before && step.after) step.entered = &spans_[(next_ - 1) / 2].enter;
        return step;
    }

private:
    const HitRecord& end(std::size_t index) const {
        const Span& span = spans_[index / 2];
        return index % 2 == 0 ? span.enter : span.exit;
    }

    const SpanList& spans_;
    std::size_t end_;
    std::size_t next_ = 0;
    bool inside_ = false;
};

bool classify(BooleanOperation operation, bool first, bool second) {
    switch (operation) {
        case BooleanOperation::Union:
            return first || second;
        case BooleanOperation::Intersection:
            return first && second;
        case BooleanOperation::Difference:
            return first && !second;
    }
    return false;
}

HitRecord flipped(const HitRecord& record) {
    HitRecord result = record;
    result.flip_normal = !result.flip_normal;
    return result;
}

/// The record of the result's end when the classification changes within a group: the end of
/// an operand whose own change caused it, the first operand's at a tie. For a difference the
/// second operand causes an enter by leaving and an exit by entering, with its normal flipped.
HitRecord boundary_record(BooleanOperation operation, const OperandStep& first,
                          const OperandStep& second, bool entering) {
    const bool first_changed =
        entering ? (!first.before && first.after) : (first.before && !first.after);
    if (first_changed) return entering ? *first.entered : *first.exited;
    if (operation == BooleanOperation::Difference)
        return flipped(entering ? *second.exited : *second.entered);
    return entering ? *second.entered : *second.exited;
}

/// A touching point of the result where it is outside on both sides of the group, or null.
/// A zero-length span of one operand (a tangent) survives where it lies on the result's
/// surface: anywhere for a union; strictly inside the other operand for an intersection (two
/// solids that touch, even where a ray is tangent to both, intersect in nothing); where the
/// subtracted operand's closed set does not reach for a difference (A - A is empty).
const Span* touching_point(BooleanOperation operation, const OperandStep& first,
                           const OperandStep& second) {
    switch (operation) {
        case BooleanOperation::Union:
            return first.point != nullptr ? first.point : second.point;
        case BooleanOperation::Intersection:
            if (first.point != nullptr && second.before && second.after) return first.point;
            if (second.point != nullptr && first.before && first.after) return second.point;
            return nullptr;
        case BooleanOperation::Difference: {
            const bool second_closed = second.before || second.after || second.touched;
            return first.point != nullptr && !second_closed ? first.point : nullptr;
        }
    }
    return nullptr;
}

/// The sweep of combine_spans. The visitor is told each group's t before it is processed
/// (`group`, false stops), each change of classification (`boundary`) and each touching point
/// (`point`); either may return false to stop.
template <class Visitor>
void sweep(BooleanOperation operation, const SpanList& first_spans, const SpanList& second_spans,
           const Ray& ray, double relative, Visitor& visitor) {
    Cursor first(first_spans);
    Cursor second(second_spans);
    const double scale = origin_over_direction(ray);
    while (!first.done() || !second.done()) {
        const double first_t = first.next_t();
        const double second_t = second.next_t();
        const double t = first_t <= second_t ? first_t : second_t;
        if (!visitor.group(t)) return;
        // A group is every end within the tolerance of its earliest one; the negated tests
        // step an operand with a NaN end rather than skipping it forever.
        const double limit = t + coincidence_tolerance(relative, scale, t);
        const OperandStep a = !(first_t > limit) ? first.advance(limit) : first.stay();
        const OperandStep b = !(second_t > limit) ? second.advance(limit) : second.stay();
        const bool before = classify(operation, a.before, b.before);
        const bool after = classify(operation, a.after, b.after);
        if (before != after) {
            if (!visitor.boundary(boundary_record(operation, a, b, after), after)) return;
        } else if (!before) {
            const Span* point = touching_point(operation, a, b);
            if (point != nullptr && !visitor.point(*point)) return;
        }
    }
}

struct ListBuilder {
    SpanList& result;

    bool group(double) { return true; }
    bool boundary(const HitRecord& record, bool entering) {
        // The classification alternates and starts outside, so every exit has its enter.
        if (entering) {
            result.push_back(Span{record, HitRecord{}});
        } else {
            result.back().exit = record;
        }
        return true;
    }
    bool point(const Span& span) {
        result.push_back(span);
        return true;
    }
};

struct FirstBoundary {
    const Ray& ray;
    HitRecord& first;
    bool found = false;

    // Ends come in increasing t, so nothing after t_max can be the first hit.
    bool group(double t) { return !(t > ray.t_max); }
    bool boundary_at(const HitRecord& record) {
        if (record.shape == nullptr || !ray.in_range(record.t)) return true;
        first = record;
        found = true;
        return false;
    }
    bool boundary(const HitRecord& record, bool) { return boundary_at(record); }
    bool point(const Span& span) { return boundary_at(span.enter); }
};

}  // namespace

double span_coincidence_tolerance(const Ray& ray, double t, double relative) {
    return coincidence_tolerance(relative, origin_over_direction(ray), t);
}

double span_coincidence_relative(const Shape& first, const Shape& second) {
    return holds_float_mesh({&first, &second}) ? kFloatSpanCoincidence : kDoubleSpanCoincidence;
}

double span_coincidence_relative(std::span<const std::shared_ptr<const Shape>> shapes) {
    std::vector<const Shape*> roots;
    roots.reserve(shapes.size());
    for (const auto& shape : shapes) roots.push_back(shape.get());
    return holds_float_mesh(std::move(roots)) ? kFloatSpanCoincidence : kDoubleSpanCoincidence;
}

void combine_spans(BooleanOperation operation, const SpanList& first, const SpanList& second,
                   const Ray& ray, SpanList& result, double relative) {
    result.clear();
    ListBuilder builder{result};
    sweep(operation, first, second, ray, relative, builder);
}

bool first_combined_boundary(BooleanOperation operation, const SpanList& first,
                             const SpanList& second, const Ray& ray, HitRecord& boundary,
                             double relative) {
    FirstBoundary finder{ray, boundary};
    sweep(operation, first, second, ray, relative, finder);
    return finder.found;
}

}  // namespace csgrt
