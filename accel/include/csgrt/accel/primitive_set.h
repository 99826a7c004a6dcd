#pragma once

#include <concepts>
#include <cstddef>

#include "csgrt/core/aabb.h"
#include "csgrt/core/hit.h"
#include "csgrt/core/query_scratch.h"
#include "csgrt/core/ray.h"

namespace csgrt {

/// What every acceleration structure is written against: a set of primitives it can bound,
/// split and test one at a time, without knowing what they are (the leaf-callback split of
/// madmann91/bvh; CGAL's AABBPrimitive concept). TriangleSet<float>, TriangleSet<double> and
/// ShapeSet model it.
///
/// - `size()`: the number of primitives, indexed 0 .. size()-1.
/// - `bounds(i)`: a conservative box of primitive i, in double.
/// - `centroid(i)`: a representative point of primitive i (for splitting and binning).
/// - `prepare(ray, scratch)`: per-ray precomputation, done once per query (for triangles the
///   shear of Woop et al. 2013). The prepared ray keeps the interval [t_min, t_max].
/// - `intersect(i, prepared, record)`: tests primitive i against the ray, with record.t as the
///   current upper bound. It writes the hit into `record` and returns true only if
///   t >= t_min and the hit beats the record: t < record.t, or t == record.t and the set's tie
///   rule prefers it (lower primitive index for triangles, lower member index for shapes).
///   So the nearest hit, ties included, never depends on the order primitives are tested in,
///   and every structure returns the same primitive. It writes at least t, primitive (or
///   object for shape sets), u and v.
/// - `occluded(i, prepared)`: whether primitive i is hit anywhere in [t_min, t_max].
/// Callers start with `record.t = ray.t_max` and `record.primitive = kNoIndex`, so a hit at
/// exactly t_max counts: the interval is closed at both ends.
template <class Set>
concept PrimitiveSet = requires(const Set& set, std::size_t i, const Ray& ray,
                                QueryScratch& scratch, const typename Set::PreparedRay& prepared,
                                HitRecord& record) {
    { set.size() } -> std::convertible_to<std::size_t>;
    { set.bounds(i) } -> std::convertible_to<Aabb>;
    { set.centroid(i) } -> std::convertible_to<Point3>;
    { set.prepare(ray, scratch) } -> std::same_as<typename Set::PreparedRay>;
    { set.intersect(i, prepared, record) } -> std::same_as<bool>;
    { set.occluded(i, prepared) } -> std::same_as<bool>;
};

}  // namespace csgrt
