#include "csgrt/core/shape.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "csgrt/core/instance.h"

namespace csgrt {

QueryScratch& thread_query_scratch() {
    thread_local QueryScratch scratch;
    return scratch;
}

void Shape::find_spans(const Ray&, SpanList& spans, QueryScratch&) const {
    spans.clear();
}

bool Shape::contains(const Point3&) const {
    return false;
}

Hit Shape::finish(const Ray&, const HitRecord&) const {
    // Only leaves put themselves into a HitRecord, so a composite is never asked to finish one.
    throw std::logic_error(std::string("csgrt: finish() called on composite shape '") +
                           std::string(kind()) + "'");
}

std::optional<Hit> Shape::intersect(const Ray& ray) const {
    if (!is_valid(ray)) return std::nullopt;
    QueryScratch& scratch = thread_query_scratch();
    scratch.reset();
    HitRecord record;
    if (!nearest_hit(ray, record, scratch)) return std::nullopt;
    return finish_hit(ray, record, scratch);
}

bool Shape::occluded(const Ray& ray) const {
    if (!is_valid(ray)) return false;
    QueryScratch& scratch = thread_query_scratch();
    scratch.reset();
    return any_hit(ray, scratch);
}

SpanList Shape::spans(const Ray& ray) const {
    SpanList spans;
    if (!is_valid(ray) || !is_solid()) return spans;
    QueryScratch& scratch = thread_query_scratch();
    scratch.reset();
    find_spans(ray, spans, scratch);
    return spans;
}

namespace {

// The leaf's hit with at least the double-precision point error (kDoubleHitErrorUlps); a leaf
// that knows a larger one (a float mesh) has set it already.
Hit finish_leaf(const Ray& ray, const HitRecord& record) {
    Hit hit = record.shape->finish(ray, record);
    double magnitude = std::max(hit.point.cwiseAbs().maxCoeff(), ray.origin.cwiseAbs().maxCoeff());
    const Aabb bounds = record.shape->bounds();
    if (!bounds.is_empty() && bounds.is_finite()) {
        magnitude = std::max(
            {magnitude, bounds.lower.cwiseAbs().maxCoeff(), bounds.upper.cwiseAbs().maxCoeff()});
    }
    if (std::isfinite(magnitude)) {
        hit.point_error =
            std::max(hit.point_error, kDoubleHitErrorUlps * kUnitRoundoff * magnitude);
    }
    return hit;
}

// Walks the instance path outermost first: each instance maps the ray into its object space,
// the leaf finishes there, and each instance maps the hit back on the way out.
Hit finish_along_path(const Ray& ray, const HitRecord& record, std::uint32_t path,
                      const QueryScratch& scratch) {
    if (path == kNoIndex) return finish_leaf(ray, record);
    const QueryScratch::PathNode& node = scratch.path_node(path);
    const Ray object_ray = node.instance->object_from_world().apply(ray);
    return node.instance->to_world(finish_along_path(object_ray, record, node.inner, scratch));
}

}  // namespace

Hit finish_hit(const Ray& ray, const HitRecord& record, const QueryScratch& scratch) {
    Hit hit = finish_along_path(ray, record, record.instance_path, scratch);
    hit.object_id = record.object;
    if (record.material != kNoPaintedMaterial) hit.material = record.material;
    if (record.flip_normal) {
        hit.geometric_normal = -hit.geometric_normal;
        hit.shading_normal = -hit.shading_normal;
        hit.front_face = !hit.front_face;
    }
    return hit;
}

}  // namespace csgrt
