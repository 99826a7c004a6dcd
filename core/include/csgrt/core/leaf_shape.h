#pragma once

#include <cstdint>
#include <optional>

#include "csgrt/core/query_cost.h"
#include "csgrt/core/shape.h"

namespace csgrt {

/// The nearest crossing of a ray with a leaf surface in [t_min, t_max]: what a leaf's
/// intersection routine reports before the hit is finished. `primitive`, u and v are the
/// leaf's own (a face, a cap, barycentrics) and go into HitRecord unchanged.
struct Crossing {
    double t = kInfinity;
    std::uint32_t primitive = 0;
    float u = 0.0f;
    float v = 0.0f;
};

/// What a leaf computes to finish a hit: the point on its surface (the rounding of o + t d
/// along the normal removed), its unit normal as the surface defines it (outward for solids)
/// and its uv. The rest of a Hit (t, the ids, the shading normal of an analytic surface,
/// which side was hit) is the same for every leaf and written once, by LeafShape::finish.
struct SurfacePoint {
    Point3 point;
    Normal3 normal;
    Vector2 uv;
};

namespace detail {

/// The two hit queries of a leaf shape written once, from the one routine each leaf has:
/// `std::optional<Crossing> Derived::crossing(const Ray&) const`, the nearest crossing in
/// [t_min, t_max] (pbrt-v4's BasicIntersect pattern). `nearest_hit` stores it as the record;
/// `any_hit` asks whether there is one. A leaf whose `any_hit` could stop earlier than its
/// nearest crossing overrides it; none of the analytic shapes can (their crossing is one root
/// choice), so none does.
///
/// `finish` is written once too, from `SurfacePoint Derived::surface_at(const Ray&, const
/// HitRecord&) const` (the record is one this leaf made for this ray): the shading normal is
/// the geometric one and front_face says whether the ray arrives against it.
///
/// The queries are defined below the class, not in it, so that a leaf's header can say
/// `extern template class detail::LeafShape<Leaf>;` and its source instantiate them where
/// `crossing` is defined and can be inlined: one virtual call per shape, as before, and no
/// other call.
template <class Derived>
class LeafShape : public Shape {
public:
    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override;
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override;
    Hit finish(const Ray& ray, const HitRecord& record) const final;
};

template <class Derived>
bool LeafShape<Derived>::nearest_hit(const Ray& ray, HitRecord& record,
                                     QueryScratch& scratch) const {
    count_solve(scratch, *this);
    const std::optional<Crossing> crossing = static_cast<const Derived&>(*this).crossing(ray);
    if (!crossing) return false;
    record = HitRecord{.t = crossing->t,
                       .shape = this,
                       .primitive = crossing->primitive,
                       .u = crossing->u,
                       .v = crossing->v};
    return true;
}

template <class Derived>
bool LeafShape<Derived>::any_hit(const Ray& ray, QueryScratch& scratch) const {
    count_solve(scratch, *this);
    return static_cast<const Derived&>(*this).crossing(ray).has_value();
}

template <class Derived>
Hit LeafShape<Derived>::finish(const Ray& ray, const HitRecord& record) const {
    const SurfacePoint surface = static_cast<const Derived&>(*this).surface_at(ray, record);
    Hit hit;
    hit.t = record.t;
    hit.point = surface.point;
    hit.geometric_normal = surface.normal;
    hit.shading_normal = surface.normal;
    hit.uv = surface.uv;
    hit.shape = this;
    hit.primitive_id = record.primitive;
    hit.front_face = ray.direction.dot(surface.normal) < 0.0;
    return hit;
}

}  // namespace detail

}  // namespace csgrt
