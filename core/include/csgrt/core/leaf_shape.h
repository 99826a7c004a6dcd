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

namespace detail {

/// The two hit queries of a leaf shape written once, from the one routine each leaf has:
/// `std::optional<Crossing> Derived::crossing(const Ray&) const`, the nearest crossing in
/// [t_min, t_max] (pbrt-v4's BasicIntersect pattern). `nearest_hit` stores it as the record;
/// `any_hit` asks whether there is one. A leaf whose `any_hit` could stop earlier than its
/// nearest crossing overrides it; none of the analytic shapes can (their crossing is one root
/// choice), so none does.
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

}  // namespace detail

}  // namespace csgrt
