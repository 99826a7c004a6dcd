#pragma once

#include <memory>

#include "csgrt/core/shape.h"
#include "csgrt/core/transform.h"

namespace csgrt {

/// A shape placed by an affine transform: the "generic object" technique (Suffern, "Ray Tracing
/// from the Ground Up", 2007, ch. 21). The world ray is mapped into object space without
/// renormalising its direction, so a root t found there is the same t in world space; normals
/// come back by the inverse transpose. The shape may be shared by many instances.
class Instance final : public Shape {
public:
    /// Throws InvalidParameter for a null shape.
    Instance(std::shared_ptr<const Shape> shape, const Transform& world_from_object);

    std::string_view kind() const override { return "instance"; }
    Aabb bounds() const override { return bounds_; }
    bool is_solid() const override { return shape_->is_solid(); }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override;
    bool contains(const Point3& p) const override;

    /// Maps a hit finished in object space (for object_from_world applied to `world_ray`) to
    /// world space.
    Hit to_world(const Hit& object_hit) const;

    /// The one shape under the transform.
    std::vector<const Shape*> children() const override { return {shape_.get()}; }
    const Shape& shape() const { return *shape_; }
    const std::shared_ptr<const Shape>& shared_shape() const { return shape_; }
    const Transform& world_from_object() const { return world_from_object_; }
    const Transform& object_from_world() const { return object_from_world_; }

private:
    std::shared_ptr<const Shape> shape_;
    Transform world_from_object_;
    Transform object_from_world_;
    Aabb bounds_;
};

}  // namespace csgrt
