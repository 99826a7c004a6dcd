#pragma once

#include <memory>
#include <span>

#include "csgrt/core/hit.h"
#include "csgrt/core/ray.h"
#include "csgrt/core/span.h"

namespace csgrt {

/// The three boolean operations of constructive solid geometry. They are regularised
/// (Requicha, "Representations for Rigid Solids", ACM Computing Surveys 12(4), 1980): the
/// result is the closure of the interior of the plain set operation, so A - A is empty and two
/// solids sharing a face unite without an internal surface (docs/csg.md).
enum class BooleanOperation { Union, Intersection, Difference };

/// The number of unit roundoffs in span_coincidence_tolerance. Measured: a Sphere and the same
/// sphere as a scaled, moved Instance give roots up to 10 ulps apart at steep incidence and up
/// to 30 ulps at incidence down to cos = 1/16 (about 4 degrees from grazing); 256 covers that
/// with margin while staying far below any feature a model means to have.
inline constexpr double kSpanCoincidenceUlps = 256.0;

/// The relative coincidence tolerance of operands whose surfaces are computed in double
/// (analytic shapes, double meshes, and booleans, instances and compounds of them).
inline constexpr double kDoubleSpanCoincidence = kSpanCoincidenceUlps * kUnitRoundoff;

/// The relative coincidence tolerance when an operand holds a float mesh: 64 unit roundoffs
/// of float (2^-18). The float triangle test rounds the ray's origin and the corners' offsets
/// from it to float, so a float face lying exactly on a double face (a box's) is found float
/// ulps away from it; with the double tolerance the two did not merge and a difference left a
/// sliver surface there. Measured against CGAL's exact booleans (a box minus a float cube
/// sharing five faces, 2,100 rays, at the origin and 2^11 away): none from 2 float ulps on at
/// the origin and from 8 at 2^11; 64 keeps a factor 8 in hand, while 256 merges ends of nearby
/// faces that are really apart (tests/csg/mesh_boolean_reference_test.cpp).
inline constexpr double kFloatSpanCoincidence = 64.0 * 0x1.0p-24;

/// How far apart, in t along `ray`, two span ends may be and still count as the same surface:
/// `relative` (kDoubleSpanCoincidence or kFloatSpanCoincidence, span_coincidence_relative) of
/// the coordinates involved, |t| + max|origin| / max|direction| (zero for an infinite t). Ends
/// closer than this are merged by the tie rules of docs/csg.md; a span shorter than this is a
/// touching point.
double span_coincidence_tolerance(const Ray& ray, double t,
                                  double relative = kDoubleSpanCoincidence);

/// The relative coincidence tolerance for combining the spans of these two operands: float's
/// when either holds a float Mesh anywhere beneath it (through instances, booleans, compounds),
/// double's otherwise. Walks the operands' trees once (shared members once); for building a
/// node, never on a query's path.
double span_coincidence_relative(const Shape& first, const Shape& second);
/// The same for the members of a union whose spans are combined together (a Compound's
/// children): float's when any of them holds a float Mesh beneath it.
double span_coincidence_relative(std::span<const std::shared_ptr<const Shape>> shapes);

/// Combines two operands' span lists along `ray` by `operation` into `result` (cleared first)
/// as Roth's CombineSegs does ("Ray Casting for Modeling Solids", CGIP 18, 1982): the ends are
/// swept in t order and each stretch between them is classified by the operation applied to the
/// operands' classifications. Each list must be sorted and disjoint (the Span contract).
///
/// The result is regularised along the ray: stretches of equal classification merge, ends
/// within span_coincidence_tolerance count as one, and a zero-length operand span survives only
/// as a touching point of the result's surface (a tangent ray). Every result end is a record of
/// one operand, preferring the first operand at a tie; ends of the second operand of a
/// difference have `flip_normal` toggled. Only `ray`'s origin and direction are used;
/// `relative` sizes the coincidence tolerance (span_coincidence_tolerance).
void combine_spans(BooleanOperation operation, const SpanList& first, const SpanList& second,
                   const Ray& ray, SpanList& result, double relative = kDoubleSpanCoincidence);

/// The first end of combine_spans' result whose t lies in [ray.t_min, ray.t_max] and that
/// belongs to a surface (ends with a null shape are unbounded and never hit), found without
/// building the list: the sweep stops there. False when there is none; `boundary` is then
/// untouched.
bool first_combined_boundary(BooleanOperation operation, const SpanList& first,
                             const SpanList& second, const Ray& ray, HitRecord& boundary,
                             double relative = kDoubleSpanCoincidence);

}  // namespace csgrt
