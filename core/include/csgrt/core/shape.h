#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "csgrt/core/aabb.h"
#include "csgrt/core/hit.h"
#include "csgrt/core/query_scratch.h"
#include "csgrt/core/ray.h"
#include "csgrt/core/span.h"

namespace csgrt {

/// Anything a ray can hit: analytic primitives, part objects, instances, meshes, compounds and
/// CSG nodes. Shapes are immutable once constructed, so every query is const and thread-safe
/// (each thread brings its own QueryScratch).
///
/// The three queries cost only what their answer needs (docs/architecture.md):
/// - `nearest_hit` records the nearest hit in [t_min, t_max] as a HitRecord (t and ids);
///   normals and uv are computed once, by `finish_hit`, for the hit that wins;
/// - `any_hit` answers occlusion: it may stop at the first hit and computes nothing else;
/// - `find_spans` lists the intervals inside a solid, which only CSG asks for.
///
/// Dispatch is one virtual call per shape per ray. Triangles of a mesh are not shapes: a mesh
/// is one shape whose structure intersects its triangles without virtual calls.
///
/// The query functions assume a valid ray (`is_valid`); the convenience functions
/// `intersect`, `occluded` and `spans` check it and answer "no hit" otherwise.
class Shape {
public:
    virtual ~Shape() = default;

    /// A short lowercase name of the kind ("sphere", "part_torus", "difference").
    virtual std::string_view kind() const = 0;

    /// Conservative bounds in the shape's own space (Aabb::infinite() for unbounded shapes).
    virtual Aabb bounds() const = 0;

    /// True for closed solids: `find_spans` and `contains` are defined and the shape may be a
    /// CSG operand.
    virtual bool is_solid() const { return false; }

    /// The shapes this one is made of, in order (an instance's shape, a boolean's operands, a
    /// compound's children); empty for a leaf. For walking a tree (counting, printing), never
    /// on a query's path: it allocates.
    virtual std::vector<const Shape*> children() const { return {}; }

    /// Finds the nearest hit with t in [ray.t_min, ray.t_max]. On success overwrites `record`
    /// (every field) and returns true; otherwise leaves `record` alone. Callers narrow
    /// ray.t_max to the best t so far before asking the next shape.
    virtual bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const = 0;

    /// True when some hit has t in [ray.t_min, ray.t_max]; agrees with `nearest_hit`.
    virtual bool any_hit(const Ray& ray, QueryScratch& scratch) const = 0;

    /// For solids: replaces `spans` with the intervals along the ray's whole line where it is
    /// inside the solid, keeping every interval that overlaps [t_min, t_max] (and possibly
    /// others). Ends are not clipped to the ray's interval. Ends inside it are exact; an end
    /// outside it lies on the correct side but may be an operand's end rather than the true
    /// surface (CSG nodes combine operands that omit spans outside the interval). The first
    /// span boundary in [t_min, t_max] is the hit `nearest_hit` reports. Non-solids leave
    /// `spans` empty.
    virtual void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const;

    /// For solids: whether point p (in the shape's space) is inside. Points on the surface
    /// may be classified either way. Non-solids contain nothing.
    virtual bool contains(const Point3& p) const;

    /// Completes a record that this leaf produced for `ray` (given in this shape's space):
    /// point, unit normals, uv, front_face, and the ids. Only leaves are ever asked.
    virtual Hit finish(const Ray& ray, const HitRecord& record) const;

    /// The nearest hit in [t_min, t_max], finished; nothing for an invalid ray. Uses this
    /// thread's scratch.
    std::optional<Hit> intersect(const Ray& ray) const;
    /// Whether anything is hit in [t_min, t_max]; false for an invalid ray.
    bool occluded(const Ray& ray) const;
    /// The spans of a solid along `ray` (empty for an invalid ray or a non-solid). Instance
    /// paths in the records are only meaningful until this thread's next query.
    SpanList spans(const Ray& ray) const;
};

/// Finishes `record`, found for `ray` with `scratch`: maps the ray down the record's instance
/// path to the leaf, lets the leaf finish the hit, maps the result back up and flips the
/// normals of surfaces that a CSG difference subtracted.
Hit finish_hit(const Ray& ray, const HitRecord& record, const QueryScratch& scratch);

}  // namespace csgrt
