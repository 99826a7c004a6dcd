#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/reference/cgal_reference.h"
#include "support/answer_tally.h"

namespace csgrt::test {

/// Tallies of one structure's answers against CGAL's exact predicates. Its ambiguous answers
/// are disagreements on hit/miss or on the nearest primitive where the ray passes within the
/// ambiguity band of an edge: expected at the precision used; counted and printed. A nearest
/// hit on another primitive at another point (beyond the band) counts as a wrong t.
struct ReferenceTally : AnswerTally {
    /// The structure's hits.
    long hits = 0;
    /// Hits on another primitive than the reference's at the same point (to the band): a
    /// shared edge or vertex, or a ray along a face. Right answers; counted apart.
    long tied = 0;

    void print(const std::string& label) const {
        std::printf(
            "[reference] %-40s rays %ld hits %ld tied %ld ambiguous %ld clear %ld max rel t err "
            "%.3g\n",
            label.c_str(), rays, hits, tied, ambiguous, disagreements(), max_relative_error);
    }
};

/// Distance, in long double, from where the ray's line meets triangle i's plane to the
/// triangle's boundary (its nearest edge line).
template <class Real>
long double distance_to_boundary(const TriangleSet<Real>& set, std::size_t i, const Ray& ray) {
    using LongVector = Eigen::Matrix<long double, 3, 1>;
    const LongVector a = set.corner(i, 0).template cast<long double>();
    const LongVector b = set.corner(i, 1).template cast<long double>();
    const LongVector c = set.corner(i, 2).template cast<long double>();
    const LongVector o = ray.origin.cast<long double>();
    const LongVector d = ray.direction.cast<long double>();
    const LongVector normal = (b - a).cross(c - a);
    const long double denominator = normal.dot(d);
    if (denominator == 0) return 0;  // in the plane's direction: always ambiguous
    const LongVector p = o + d * (normal.dot(a - o) / denominator);
    long double distance = std::numeric_limits<long double>::infinity();
    const LongVector corners[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        const LongVector edge = corners[(k + 1) % 3] - corners[k];
        distance = std::min(distance, edge.cross(p - corners[k]).norm() / edge.norm());
    }
    return distance;
}

/// |cos| of the angle between the ray and triangle i's normal, in long double.
template <class Real>
long double incidence_cosine(const TriangleSet<Real>& set, std::size_t i, const Ray& ray) {
    using LongVector = Eigen::Matrix<long double, 3, 1>;
    const LongVector a = set.corner(i, 0).template cast<long double>();
    const LongVector normal = (set.corner(i, 1).template cast<long double>() - a)
                                  .cross(set.corner(i, 2).template cast<long double>() - a);
    const LongVector d = ray.direction.cast<long double>();
    return std::abs(normal.dot(d)) / (normal.norm() * d.norm());
}

/// The width of the ambiguity band for a ray near triangle i. The watertight test decides in
/// the plane perpendicular to the ray, after shearing coordinates of magnitude M (origin and
/// corners): there the ray's footprint is known to about `ulps` roundoffs of Real times M. In
/// the triangle's own plane that uncertainty is stretched by 1 / |cos theta| (theta between
/// the ray and the normal), so grazing rays have wide bands and head-on rays narrow ones.
template <class Real>
long double ambiguity_band(const TriangleSet<Real>& set, std::size_t i, const Ray& ray,
                           double ulps = 64.0) {
    const double unit = std::numeric_limits<Real>::epsilon() * 0.5;
    double magnitude = ray.origin.norm();
    for (int k = 0; k < 3; ++k) {
        magnitude = std::max(magnitude, set.corner(i, k).template cast<double>().norm());
    }
    const long double cosine = std::max(incidence_cosine(set, i, ray), 1e-300L);
    return ulps * unit * magnitude / cosine;
}

/// Judges one answer of a structure (`hit`, and `record` when it hit) against CGAL's exact
/// answer `exact` for the same ray, and tallies it. Hit/miss and the nearest primitive must
/// agree unless the ray is within the ambiguity band of an involved triangle. When both name
/// the same primitive, the hit points along the ray must agree to the band's width:
/// |t - t_exact| |d| <= ambiguity_band (the same derivation: an error of the footprint becomes
/// an error along the ray stretched by 1 / |cos theta|).
///
/// `t_must_agree` is for rays along faces and edges (axis rays on an integer mesh): they meet
/// triangles on their boundary or lie in their plane, which the band excuses, yet where both
/// hit, the first point where the ray meets the surface is the same whichever triangle names it
/// (CgalReference's in-plane t is the near end of the overlap). With it, a hit on another
/// primitive is excused only if its t is the reference's to the band.
template <class Real>
void judge_against_reference(const TriangleSet<Real>& set, const CgalReference& reference,
                             const Ray& ray, bool hit, const HitRecord& record,
                             const std::optional<CgalReference::Answer>& exact,
                             ReferenceTally& tally, bool t_must_agree = false) {
    ++tally.rays;
    if (hit) ++tally.hits;
    if (exact) ++tally.reference_hits;
    auto in_band = [&](std::uint32_t primitive) {
        return distance_to_boundary(set, primitive, ray) <= ambiguity_band(set, primitive, ray);
    };
    if (hit != exact.has_value()) {
        const std::uint32_t primitive = hit ? record.primitive : exact->primitive;
        bool ambiguous = in_band(primitive);
        // A miss by the structure is also excused when every exactly-hit triangle is in the band.
        if (!ambiguous && !hit) {
            ambiguous = true;
            for (std::uint32_t p : reference.intersected_primitives(ray)) ambiguous &= in_band(p);
        }
        if (!ambiguous && std::getenv("CSGRT_DEBUG_REFERENCE"))
            std::printf("hitmiss hit=%d prim=%u dist=%Lg band=%Lg\n", hit, primitive,
                        distance_to_boundary(set, primitive, ray),
                        ambiguity_band(set, primitive, ray));
        (ambiguous ? tally.ambiguous : hit ? tally.false_hits : tally.false_misses)++;
        return;
    }
    if (!hit) return;
    if (record.primitive != exact->primitive) {
        // Two triangles met at the same point (a shared edge) or one of them is in the band.
        const double gap = std::abs(record.t - exact->t) * ray.direction.norm();
        if (gap <= ambiguity_band(set, exact->primitive, ray)) {
            ++tally.tied;
            return;
        }
        const bool ambiguous =
            !t_must_agree && (in_band(record.primitive) || in_band(exact->primitive));
        if (!ambiguous && std::getenv("CSGRT_DEBUG_REFERENCE"))
            std::printf("prim %u vs %u t %.17g vs %.17g gap %g\n", record.primitive,
                        exact->primitive, record.t, exact->t, gap);
        (ambiguous ? tally.ambiguous : tally.wrong_t)++;
        return;
    }
    const double error = std::abs(record.t - exact->t) / std::max(1e-300, std::abs(exact->t));
    tally.max_relative_error = std::max(tally.max_relative_error, error);
    const double distance = std::abs(record.t - exact->t) * ray.direction.norm();
    if (distance > ambiguity_band(set, exact->primitive, ray)) {
        if (std::getenv("CSGRT_DEBUG_REFERENCE"))
            std::printf("t %.17g vs %.17g err %g\n", record.t, exact->t, error);
        ++tally.wrong_t;
    }
}

/// Queries `structure` with one ray and judges its answer against CGAL's (computed here; see
/// ReferenceAnswers to compute it once for many structures).
template <class Real>
void compare_with_reference(const Accelerator<TriangleSet<Real>>& structure,
                            const TriangleSet<Real>& set, const CgalReference& reference,
                            const Ray& ray, QueryScratch& scratch, ReferenceTally& tally) {
    HitRecord record;
    const bool hit = structure.intersect(ray, record, scratch);
    judge_against_reference(set, reference, ray, hit, record, reference.nearest(ray), tally);
}

/// CGAL answers rays and segments, not whole lines: a t_min of -infinity becomes one far enough
/// back to put the whole of `box` inside the interval.
inline void bound_for_reference(std::vector<Ray>& rays, const Aabb& box) {
    const double reach = box.diagonal().norm();
    for (Ray& ray : rays) {
        if (ray.t_min == -kInfinity)
            ray.t_min = -2.0 * ((ray.origin - box.center()).norm() + reach) / ray.direction.norm();
    }
}

/// Rays with CGAL's exact nearest answer for each, computed once so that every structure and
/// both precisions are judged against it without paying for CGAL again (the sets judged must
/// hold the corners the reference was built over: float-representable ones serve both).
struct ReferenceAnswers {
    std::vector<Ray> rays;
    std::vector<std::optional<CgalReference::Answer>> exact;

    ReferenceAnswers(const CgalReference& reference, std::vector<Ray> rays_in)
        : rays(std::move(rays_in)) {
        exact.reserve(rays.size());
        for (const Ray& ray : rays) exact.push_back(reference.nearest(ray));
    }
};

}  // namespace csgrt::test
