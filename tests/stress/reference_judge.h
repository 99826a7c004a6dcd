#pragma once

// What the long double reference shapes (reference_shapes.h) say a ray should hit, with the
// ambiguity bands inside which a double computation may answer either way: the judge of
// every test that compares shapes against the reference (shape_accuracy_test.cpp,
// structure_shapes_reference_test.cpp).
//
// The tolerances, in units of the point scale s(t) = u (|o| + |t| |d| + |c| + size) (u = 2^-53,
// c the object's centre): the rounding of a point's coordinates, below which no double
// computation can place a hit.
// - A root-finder that is backward stable returns the exact crossing of a ray whose points are
//   off by a few roundings of s: mapping the ray into object space (3 roundings of |o| + |c| per
//   coordinate), moving the origin to the closest approach (2), evaluating the surface's
//   function there (about 8 of its terms, which are of the object's size) and the last
//   o + t d (2); 15 in all. Along the ray that becomes s / (|d| cos a), a the angle between
//   the ray and the normal. kRootUlps = 32 allows twice that; 4 ulps of t cover the division
//   that forms t.
// - A crossing within kTrimBand = 2 kRootUlps point scales / cos a of a trim (an edge, a rim,
//   an angle limit) may land on either side of it: ambiguous, counted, not judged.
// - A line within kTangentBand = 64 point scales of touching a curved surface is ambiguous
//   (touch or near miss; the torus's measured band is 2-4, docs/accuracy.md), and so is a line
//   through a cone's apex within sqrt(u) relative (the cone attributes hits that close to the
//   apex, docs/shapes.md).

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"
#include "stress/reference_shapes.h"

namespace csgrt::test {

inline constexpr double kRootUlps = 32.0;
inline constexpr double kTrimBand = 2.0 * kRootUlps;
inline constexpr double kTangentBand = 64.0;

/// A shape's long double model and the sizes its rounding is measured in.
struct JudgedShape {
    std::shared_ptr<const ReferenceShape> reference;
    /// The object's centre and size in world units (they set the point scale).
    Point3 center{0.0, 0.0, 0.0};
    double size = 1.0;
    /// World units per object unit (the reference's trims are in object units): the smallest
    /// stretch of the instance transform, 1 for a shape placed by its own parameters.
    double object_scale = 1.0;
    /// The condition number |L| |L^-1| of an instance's linear map L (1 for rotations and
    /// uniform scales): mapping the ray into object space rounds its coordinates by
    /// u |L^-1| (|o| + |c|), which maps back as u cond(L) (|o| + |c|), so every point scale
    /// is multiplied by it.
    double conditioning = 1.0;
};

/// What the reference says the nearest hit in [0, inf) is.
struct Verdict {
    bool ambiguous = false;
    bool hit = false;
    Long t = 0;
    Long cosine = 1;
    /// The kept crossings at t >= 0, in order (for the spans of solids), and whether any of
    /// them (or a near tangency) is ambiguous.
    std::vector<Crossing> boundaries;
    bool boundaries_ambiguous = false;
};

/// u (|o| + |t| |d| + |c| + size), times the conditioning: the rounding of a point at t.
inline double point_scale(const Ray& ray, double t, const JudgedShape& c) {
    return c.conditioning * kUnitRoundoff *
           (ray.origin.norm() + std::abs(t) * ray.direction.norm() + c.center.norm() + c.size);
}

/// The reference's verdict on `ray` against `c`, with the ambiguity bands above.
inline Verdict judge(const JudgedShape& c, const Ray& ray) {
    LineCrossings line;
    c.reference->crossings(to_long(ray), line);
    std::sort(line.crossings.begin(), line.crossings.end(),
              [](const Crossing& a, const Crossing& b) { return a.t < b.t; });
    // Object-space distances: world distances over the instance's scale.
    const double scale = c.object_scale;
    const double length = ray.direction.norm();
    Verdict verdict;
    bool nearest_found = false;
    for (const Crossing& crossing : line.crossings) {
        const double t = static_cast<double>(crossing.t);
        const double s = point_scale(ray, t, c) / scale;
        const double cosine = std::max(static_cast<double>(crossing.cosine), 1e-300);
        const double band = kTrimBand * s / cosine;
        const double along = t * length / scale;   // object-space distance from the origin
        if (along < -band) continue;               // well behind the origin
        bool ambiguous = std::abs(along) <= band;  // the origin is on the surface
        ambiguous |= std::abs(static_cast<double>(crossing.trim_distance)) <= band;
        if (ambiguous) {
            verdict.boundaries_ambiguous = true;
            if (!nearest_found) verdict.ambiguous = true;
            nearest_found = true;
            continue;
        }
        if (crossing.t < 0 || crossing.trim_distance < 0) continue;
        verdict.boundaries.push_back(crossing);
        if (!nearest_found) {
            nearest_found = true;
            verdict.hit = true;
            verdict.t = crossing.t;
            verdict.cosine = crossing.cosine;
        }
    }
    for (const NearTangency& tangency : line.tangencies) {
        const double t = static_cast<double>(tangency.t);
        const double s = point_scale(ray, t, c) / scale;
        const bool singular = tangency.trim_distance == 0;  // an apex
        const double band =
            singular ? std::sqrt(kUnitRoundoff) * s / kUnitRoundoff : kTangentBand * s;
        if (!(tangency.distance <= band) || tangency.trim_distance < -kTrimBand * s) continue;
        // A near-tangent line crosses within about sqrt(2 rho band) of the touching point,
        // rho (the curvature radius) at most the object's size.
        const double window = 2.0 * std::sqrt(2.0 * c.size * band * scale) / length;
        if (t < -window) continue;
        verdict.boundaries_ambiguous = true;
        if (!verdict.hit || t <= static_cast<double>(verdict.t) + window) verdict.ambiguous = true;
    }
    return verdict;
}


/// How far a hit's t may lie from the reference's: kRootUlps point scales along the ray at
/// the crossing's cosine, plus 4 ulps of t.
inline double error_bound(const JudgedShape& c, const Ray& ray, double t, double cosine) {
    return kRootUlps * point_scale(ray, t, c) / (ray.direction.norm() * std::max(cosine, 1e-300)) +
           4.0 * kUnitRoundoff * std::abs(t);
}


}  // namespace csgrt::test
