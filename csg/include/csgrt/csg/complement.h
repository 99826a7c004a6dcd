#pragma once

#include <memory>
#include <vector>

#include "csgrt/core/shape.h"

namespace csgrt {

/// Everything outside a solid (CSG's "not"): the points `operand` does not contain. Its surface
/// is the operand's, with the normals flipped so that they point out of the complement, into
/// the operand. A solid, so a CSG operand: A ∩ not(B) is A − B, and not(not(A)) is A.
///
/// Unbounded (bounds() is infinite): along a ray's line the spans are the gaps between the
/// operand's spans, from -infinity and to +infinity (null shapes at those ends). They are
/// exact within [t_min, t_max], where the operand's spans are; outside it an end may be
/// further out than the true surface, on the correct side (the contract of find_spans).
class Complement final : public Shape {
public:
    /// Throws InvalidParameter when `operand` is null or not a solid.
    explicit Complement(std::shared_ptr<const Shape> operand);

    std::string_view kind() const override { return "not"; }
    Aabb bounds() const override { return Aabb::infinite(); }
    bool is_solid() const override { return true; }
    std::vector<const Shape*> children() const override { return {operand_.get()}; }

    /// The operand's nearest surface, its normal flipped: the two solids share their boundary.
    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override { return !operand_->contains(p); }

    const Shape& operand() const { return *operand_; }

private:
    std::shared_ptr<const Shape> operand_;
};

}  // namespace csgrt
