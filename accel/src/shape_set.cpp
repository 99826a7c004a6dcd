#include "csgrt/accel/shape_set.h"

#include "csgrt/core/error.h"

namespace csgrt {

ShapeSet::ShapeSet(std::vector<std::shared_ptr<const Shape>> shapes) : shapes_(std::move(shapes)) {
    bounds_.reserve(shapes_.size());
    for (std::size_t i = 0; i < shapes_.size(); ++i) {
        require(shapes_[i] != nullptr, "ShapeSet", "member " + std::to_string(i), "a shape",
                "null");
        bounds_.push_back(shapes_[i]->bounds());
    }
}

bool ShapeSet::intersect(std::size_t i, const PreparedRay& prepared, HitRecord& record) const {
    Ray ray = prepared.ray;
    ray.t_max = record.t;
    HitRecord candidate;
    if (!shapes_[i]->nearest_hit(ray, candidate, *prepared.scratch)) return false;
    const auto index = static_cast<std::uint32_t>(i);
    if (candidate.t == record.t && index >= record.object) return false;
    record = candidate;
    record.object = index;
    return true;
}

}  // namespace csgrt
