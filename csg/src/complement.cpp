#include "csgrt/csg/complement.h"

#include "csgrt/core/error.h"

namespace csgrt {

namespace {

/// An end of the operand's spans as an end of the complement's: the same surface, facing the
/// other way (a null end at infinity stays as it is).
HitRecord flipped(const HitRecord& end) {
    HitRecord record = end;
    if (record.shape != nullptr) record.flip_normal = !record.flip_normal;
    return record;
}

}  // namespace

Complement::Complement(std::shared_ptr<const Shape> operand) : operand_(std::move(operand)) {
    require(operand_ != nullptr, "Complement", "operand", "a shape", "null");
    require(operand_->is_solid(), "Complement", "operand", "a solid (is_solid())",
            operand_->kind());
}

bool Complement::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    if (!operand_->nearest_hit(ray, record, scratch)) return false;
    record.flip_normal = !record.flip_normal;
    return true;
}

bool Complement::any_hit(const Ray& ray, QueryScratch& scratch) const {
    return operand_->any_hit(ray, scratch);
}

void Complement::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    BorrowedSpans operand_spans(scratch);
    operand_->find_spans(ray, operand_spans.list(), scratch);
    spans.clear();
    // The gaps between the operand's spans, from -infinity to +infinity.
    HitRecord gap_start{.t = -kInfinity};
    for (const Span& span : operand_spans.list()) {
        // An operand span from -infinity leaves no gap before it.
        if (span.enter.shape != nullptr) spans.push_back(Span{gap_start, flipped(span.enter)});
        gap_start = flipped(span.exit);
    }
    if (gap_start.shape != nullptr || operand_spans.list().empty()) {
        spans.push_back(Span{gap_start, HitRecord{.t = kInfinity}});
    }
}

}  // namespace csgrt
