#include "csgrt/core/half_space.h"

#include "csgrt/core/error.h"

namespace csgrt {

namespace {

/// `normal`, checked in the half-space's name before the plane checks it in its own.
const Normal3& checked_normal(const Point3& point, const Normal3& normal) {
    require_finite(point, "HalfSpace", "point");
    require_finite(normal, "HalfSpace", "normal");
    require(detail::normalized_or_zero(normal).squaredNorm() > 0.0, "HalfSpace", "normal",
            "non-zero", normal);
    return normal;
}

}  // namespace

HalfSpace::HalfSpace(const Point3& point, const Normal3& normal)
    : boundary_(point, checked_normal(point, normal)) {}

void HalfSpace::find_spans(const Ray& ray, SpanList& spans, QueryScratch&) const {
    spans.clear();
    // Null shapes mark the ends at infinity, where the ray's line never meets the plane.
    const HitRecord before{.t = -kInfinity};
    const HitRecord after{.t = kInfinity};
    double t;
    if (!detail::plane_crossing(ray, boundary_.point(), boundary_.normal(), t)) {
        // Parallel (or a crossing beyond the largest double): inside along the whole line or
        // nowhere on it.
        if (contains(ray.origin)) spans.push_back(Span{before, after});
        return;
    }
    const HitRecord crossing{.t = t, .shape = this, .primitive = 0};
    if (ray.direction.dot(boundary_.normal()) > 0.0) {
        // Moving along the normal: inside until the plane, then out.
        if (t >= ray.t_min) spans.push_back(Span{before, crossing});
    } else if (t <= ray.t_max) {
        spans.push_back(Span{crossing, after});
    }
}

bool HalfSpace::contains(const Point3& p) const {
    return (p - boundary_.point()).dot(boundary_.normal()) < 0.0;
}

SurfacePoint HalfSpace::surface_at(const Ray& ray, const HitRecord& record) const {
    return boundary_.surface_at(ray, record);
}

template class detail::LeafShape<HalfSpace>;

}  // namespace csgrt
