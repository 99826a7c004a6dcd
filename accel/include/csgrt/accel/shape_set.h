#pragma once

#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include "csgrt/core/shape.h"

namespace csgrt {

/// A list of shapes as a primitive set (accel/primitive_set.h): what a compound or a scene
/// builds its hierarchy of bounding boxes over. Member i's hits carry `object = i`; ties at
/// equal t go to the lower member index.
class ShapeSet {
public:
    struct PreparedRay {
        Ray ray;
        QueryScratch* scratch;
    };

    ShapeSet() = default;
    /// Throws InvalidParameter for a null member.
    explicit ShapeSet(std::vector<std::shared_ptr<const Shape>> shapes);

    std::size_t size() const { return shapes_.size(); }
    Aabb bounds(std::size_t i) const { return bounds_[i]; }
    /// The box centre (shapes have no better representative point).
    Point3 centroid(std::size_t i) const { return bounds_[i].center(); }
    const Shape& shape(std::size_t i) const { return *shapes_[i]; }
    const std::vector<std::shared_ptr<const Shape>>& shapes() const { return shapes_; }

    PreparedRay prepare(const Ray& ray, QueryScratch& scratch) const { return {ray, &scratch}; }
    /// The member's nearest hit in [t_min, record.t]; one virtual call.
    bool intersect(std::size_t i, const PreparedRay& prepared, HitRecord& record) const;
    bool occluded(std::size_t i, const PreparedRay& prepared) const {
        return shapes_[i]->any_hit(prepared.ray, *prepared.scratch);
    }

    std::size_t bytes() const {
        return shapes_.capacity() * sizeof(shapes_[0]) + bounds_.capacity() * sizeof(Aabb);
    }

private:
    std::vector<std::shared_ptr<const Shape>> shapes_;
    std::vector<Aabb> bounds_;
};

/// The member of a set of type Set that a record of its names: a ShapeSet's hits carry it in
/// `object`, a triangle set's in `primitive`.
template <class Set>
std::uint32_t member_of(const HitRecord& record) {
    if constexpr (std::is_same_v<Set, ShapeSet>) {
        return record.object;
    } else {
        return record.primitive;
    }
}

}  // namespace csgrt
