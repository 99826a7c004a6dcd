#pragma once

#include <cstdint>
#include <memory>

#include "csgrt/core/shape.h"

namespace csgrt {

/// A shape with a material of its own: it answers every query as `shape` does, and the hits
/// it reports carry `material` (an index into the scene's materials) unless a painted shape
/// nearer the leaf already gave them one. This is how an operand of a CSG tree carries its
/// own material (POV-Ray's textures on CSG children): a surface keeps the material of the
/// operand it belongs to, so the cut surface of a difference shows the subtracted solid's
/// material (docs/rendering.md, "Materials in CSG"), and a hit with no painted shape on its
/// path has the scene object's. Spans carry the material on both ends.
class Painted final : public Shape {
public:
    /// Throws InvalidParameter for a null shape or a material index above kMaxPaintedMaterial.
    Painted(std::shared_ptr<const Shape> shape, std::uint32_t material);

    std::string_view kind() const override { return "painted"; }
    Aabb bounds() const override { return shape_->bounds(); }
    bool is_solid() const override { return shape_->is_solid(); }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override {
        return shape_->any_hit(ray, scratch);
    }
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override { return shape_->contains(p); }

    std::vector<const Shape*> children() const override { return {shape_.get()}; }
    const Shape& shape() const { return *shape_; }
    const std::shared_ptr<const Shape>& shared_shape() const { return shape_; }
    std::uint32_t material() const { return material_; }

private:
    std::shared_ptr<const Shape> shape_;
    std::uint16_t material_;
};

}  // namespace csgrt
