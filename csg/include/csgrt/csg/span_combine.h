#pragma once

#include "csgrt/core/hit.h"
#include "csgrt/core/ray.h"
#include "csgrt/core/span.h"

namespace csgrt {

/// The three boolean operations of constructive solid geometry. They are regularised
/// (Requicha, "Representations for Rigid Solids", ACM Computing Surveys 12(4), 1980): the
/// result is the closure of the interior of the plain set operation, so A - A is empty and two
/// solids sharing a face unite without an internal surface (docs/csg.md).
enum class BooleanOperation { Union, Intersection, Difference };

/// How far apart, in t along `ray`, two span ends may be and still count as the same surface:
/// kSpanCoincidenceUlps unit roundoffs of the coordinates involved, |t| + max|origin| /
/// max|direction| (zero for an infinite t). Ends closer than this are merged by the tie rules
/// of docs/csg.md; a span shorter than this is a touching point.
double span_coincidence_tolerance(const Ray& ray, double t);

/// The number of unit roundoffs in span_coincidence_tolerance. Measured: a Sphere and the same
/// sphere as a scaled, moved Instance give roots up to 10 ulps apart at steep incidence and up
/// to 30 ulps at incidence down to cos = 1/16 (about 4 degrees from grazing); 256 covers that
/// with margin while staying far below any feature a model means to have.
inline constexpr double kSpanCoincidenceUlps = 256.0;

/// Combines two operands' span lists along `ray` by `operation` into `result` (cleared first)
/// as Roth's CombineSegs does ("Ray Casting for Modeling Solids", CGIP 18, 1982): the ends are
/// swept in t order and each stretch between them is classified by the operation applied to the
/// operands' classifications. Each list must be sorted and disjoint (the Span contract).
///
/// The result is regularised along the ray: stretches of equal classification merge, ends
/// within span_coincidence_tolerance count as one, and a zero-length operand span survives only
/// as a touching point of the result's surface (a tangent ray). Every result end is a record of
/// one operand, preferring the first operand at a tie; ends of the second operand of a
/// difference have `flip_normal` toggled. Only `ray`'s origin and direction are used.
void combine_spans(BooleanOperation operation, const SpanList& first, const SpanList& second,
                   const Ray& ray, SpanList& result);

/// The first end of combine_spans' result whose t lies in [ray.t_min, ray.t_max] and that
/// belongs to a surface (ends with a null shape are unbounded and never hit), found without
/// building the list: the sweep stops there. False when there is none; `boundary` is then
/// untouched.
bool first_combined_boundary(BooleanOperation operation, const SpanList& first,
                             const SpanList& second, const Ray& ray, HitRecord& boundary);

}  // namespace csgrt
