#pragma once

#include <memory>
#include <vector>

#include "csgrt/core/shape.h"
#include "csgrt/csg/span_combine.h"

namespace csgrt {

/// A CSG node: the union, intersection or difference (first minus second) of two solids,
/// evaluated along each ray by combining the operands' span lists (Roth, "Ray Casting for
/// Modeling Solids", CGIP 18, 1982) with the tie rules of docs/csg.md. Itself a solid, so
/// nodes nest; hits name the leaf surface that produced them, and surfaces of a subtracted
/// solid have their normals flipped so that they point out of the result.
///
/// Bounds: union = the join of the operands' boxes, intersection = their overlap, difference =
/// the first operand's box. A ray that misses a node's box costs one box test; a union whose
/// operands' boxes are disjoint along the ray answers nearest_hit and any_hit from its
/// operands' own queries without span lists; an intersection or difference asks its second
/// operand only where the first has spans.
class Boolean final : public Shape {
public:
    /// Throws InvalidParameter naming the operand when it is null or not a solid.
    Boolean(BooleanOperation operation, std::shared_ptr<const Shape> first,
            std::shared_ptr<const Shape> second);

    /// "union", "intersection" or "difference".
    std::string_view kind() const override;
    Aabb bounds() const override { return bounds_; }
    bool is_solid() const override { return true; }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    /// Spans are exact within [t_min, t_max]; an end outside it is an operand's end, which may
    /// lie beyond the true surface when an operand left out spans outside the interval.
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    /// The operation applied to the operands' `contains`.
    bool contains(const Point3& p) const override;

    BooleanOperation operation() const { return operation_; }
    /// The two operands, first then second.
    std::vector<const Shape*> children() const override { return {first_.get(), second_.get()}; }
    const Shape& first() const { return *first_; }
    const Shape& second() const { return *second_; }
    const std::shared_ptr<const Shape>& shared_first() const { return first_; }
    const std::shared_ptr<const Shape>& shared_second() const { return second_; }

private:
    /// The part of `ray` inside this node's box, or false when the ray misses it.
    bool clip_to_bounds(const Ray& ray, const Vector3& inverse_direction, Ray& inside) const;
    /// For intersection and difference: the first operand's spans in `first_spans`, and in
    /// `second_spans` the second operand's spans over the stretch the first one covers. False
    /// when the result is empty along `inside`.
    /// nearest_hit (kAny false: the first boundary in [t_min, t_max] into `record`) and
    /// any_hit (kAny true: whether there is one, `record` a scratch value), written once: the
    /// same box tests, operand shortcuts and span combination in the same order.
    template <bool kAny>
    [[gnu::always_inline]] inline bool first_boundary(const Ray& ray, HitRecord& record,
                                                      QueryScratch& scratch) const;
    bool operand_spans(const Ray& inside, const Vector3& inverse_direction, SpanList& first_spans,
                       SpanList& second_spans, QueryScratch& scratch) const;

    BooleanOperation operation_;
    std::shared_ptr<const Shape> first_;
    std::shared_ptr<const Shape> second_;
    Aabb first_bounds_;
    Aabb second_bounds_;
    Aabb bounds_;
    /// The boxes' is_empty(), found once.
    bool first_empty_ = false;
    bool second_empty_ = false;
    bool bounds_empty_ = false;
    /// The operands' span coincidence tolerance (span_coincidence_relative): float-sized when
    /// either holds a float mesh.
    double coincidence_ = kDoubleSpanCoincidence;
};

/// The union of one or more solids as a balanced tree of binary nodes (depth log2 n, which
/// keeps span combining O(n log n) per ray rather than the O(n^2) of a chain). One operand is
/// returned as it is. Throws InvalidParameter for an empty list or a null or non-solid operand.
std::shared_ptr<const Shape> make_union(const std::vector<std::shared_ptr<const Shape>>& operands);

/// The intersection of one or more solids, balanced like make_union.
std::shared_ptr<const Shape> make_intersection(
    const std::vector<std::shared_ptr<const Shape>>& operands);

/// `first` minus every solid in `subtracted`, built as first - union(subtracted), which is the
/// same solid as subtracting them one by one. With nothing to subtract, `first` itself.
std::shared_ptr<const Shape> make_difference(
    std::shared_ptr<const Shape> first,
    const std::vector<std::shared_ptr<const Shape>>& subtracted);

}  // namespace csgrt
