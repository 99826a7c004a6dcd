#include "csgrt/core/instance.h"

#include "csgrt/core/error.h"

namespace csgrt {

Instance::Instance(std::shared_ptr<const Shape> shape, const Transform& world_from_object)
    : shape_(std::move(shape)),
      world_from_object_(world_from_object),
      object_from_world_(world_from_object.inverse()) {
    require(shape_ != nullptr, "Instance", "shape", "a shape", "null");
    bounds_ = world_from_object_.apply(shape_->bounds());
}

bool Instance::nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const {
    if (!shape_->nearest_hit(object_from_world_.apply(ray), record, scratch)) return false;
    record.instance_path = scratch.push_instance(this, record.instance_path);
    return true;
}

bool Instance::any_hit(const Ray& ray, QueryScratch& scratch) const {
    return shape_->any_hit(object_from_world_.apply(ray), scratch);
}

void Instance::find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const {
    shape_->find_spans(object_from_world_.apply(ray), spans, scratch);
    // Boundaries of one leaf share an inner path, so one path node usually serves them all.
    std::uint32_t last_inner = kNoIndex;
    std::uint32_t last_outer = kNoIndex;
    auto wrap = [&](HitRecord& record) {
        if (record.shape == nullptr) return;
        if (last_outer == kNoIndex || record.instance_path != last_inner) {
            last_inner = record.instance_path;
            last_outer = scratch.push_instance(this, last_inner);
        }
        record.instance_path = last_outer;
    };
    for (Span& span : spans) {
        wrap(span.enter);
        wrap(span.exit);
    }
}

bool Instance::contains(const Point3& p) const {
    return shape_->contains(object_from_world_.apply_point(p));
}

Hit Instance::to_world(const Hit& object_hit) const {
    Hit hit = object_hit;
    hit.point = world_from_object_.apply_point(object_hit.point);
    // The object-space error stretched by the map (the infinity norm of L), plus the rounding
    // of each way through it, gamma(3) of |L| |p| + |c| per coordinate: the world point's, and
    // that of a ray leaving it, whose origin is mapped back down (pbrt-v4's transform errors).
    const Eigen::Matrix3d& linear = world_from_object_.linear();
    const double stretch = linear.cwiseAbs().rowwise().sum().maxCoeff();
    const double to_world = (linear.cwiseAbs() * object_hit.point.cwiseAbs() +
                             world_from_object_.translation().cwiseAbs())
                                .maxCoeff();
    const double to_object = (object_from_world_.linear().cwiseAbs() * hit.point.cwiseAbs() +
                              object_from_world_.translation().cwiseAbs())
                                 .maxCoeff();
    hit.point_error =
        stretch * (object_hit.point_error + gamma(3) * to_object) + gamma(3) * to_world;
    hit.geometric_normal =
        world_from_object_.apply_normal(object_hit.geometric_normal).normalized();
    hit.shading_normal = world_from_object_.apply_normal(object_hit.shading_normal).normalized();
    // front_face needs no update: d_world . (L^-T n) = (L d) . (L^-T n) = d . n.
    return hit;
}

}  // namespace csgrt
