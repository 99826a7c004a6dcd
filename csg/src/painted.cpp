#include "csgrt/csg/painted.h"

#include <string>
#include <utility>

#include "csgrt/core/error.h"

namespace csgrt {

Painted::Painted(std::shared_ptr<const Shape> shape, std::uint32_t material)
    : shape_(std::move(shape)), material_(static_cast<std::uint16_t>(material)) {
    require(shape_ != nullptr, "Painted", "shape", "a shape", "null");
    require(material <= kMaxPaintedMaterial, "Painted", "material",
            "at most " + std::to_string(kMaxPaintedMaterial), material);
}

bool Painted::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    if (!shape_->nearest_hit(ray, record, scratch)) return false;
    if (record.material == kNoPaintedMaterial) record.material = material_;
    return true;
}

void Painted::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    shape_->find_spans(ray, spans, scratch);
    for (Span& span : spans) {
        // Unbounded ends (no shape) are no surface: nothing to paint.
        if (span.enter.shape != nullptr && span.enter.material == kNoPaintedMaterial)
            span.enter.material = material_;
        if (span.exit.shape != nullptr && span.exit.material == kNoPaintedMaterial)
            span.exit.material = material_;
    }
}

}  // namespace csgrt
