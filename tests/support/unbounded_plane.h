#pragma once

#include <string_view>

#include "csgrt/core/shape.h"

namespace csgrt::test {

/// The plane z = height as a shape with infinite bounds: structures keep it out of their cells
/// and nodes and test it for every ray. Hits carry primitive 0.
class UnboundedPlane final : public Shape {
public:
    explicit UnboundedPlane(double height = 0.0) : height_(height) {}

    std::string_view kind() const override { return "unbounded_plane"; }
    Aabb bounds() const override { return Aabb::infinite(); }
    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch&) const override {
        if (ray.direction.z() == 0.0) return false;
        const double t = (height_ - ray.origin.z()) / ray.direction.z();
        if (!ray.in_range(t)) return false;
        record = HitRecord{.t = t, .shape = this, .primitive = 0};
        return true;
    }
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override {
        HitRecord record;
        return nearest_hit(ray, record, scratch);
    }

private:
    double height_;
};

}  // namespace csgrt::test
