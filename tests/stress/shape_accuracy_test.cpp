// Numerical stress of every core shape and part object: at 1e-6, 1 and 1e6 scale, near and far
// (1e6 sizes) from the world origin, placed by their own parameters and by a rotating, scaling
// Instance; rays from 0.5 to 1e6 sizes away, grazing rays and rays along the axes. Every
// answer is judged against the long double model of tests/stress/reference_shapes.h.
//
// The tolerances and the ambiguity bands are stated and derived in reference_judge.h.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/core/shapes.h"
#include "stress/reference_judge.h"
#include "stress/reference_shapes.h"
#include "stress/stress_config.h"
#include "stress/summary.h"
#include "support/answer_tally.h"
#include "support/example_shapes.h"
#include "support/random.h"

namespace csgrt {
namespace {

using test::error_bound;
using test::judge;
using test::kRootUlps;
using test::Long;
using test::LongVector;
using test::point_scale;
using test::Verdict;


using ShapePointer = std::shared_ptr<const Shape>;
using ReferencePointer = std::shared_ptr<const test::ReferenceShape>;

/// One shape placed in the world, with its long double model.
struct Case : test::JudgedShape {
    std::string kind;
    std::string placement;
    bool instanced = false;
    ShapePointer shape;
    /// The world box rays aim into.
    Aabb target;
};

struct Placement {
    std::string name;
    double size;
    Point3 center;
};

const std::vector<Placement>& placements() {
    static const std::vector<Placement> list = {
        {"size 1", 1.0, Point3(0.25, -0.5, 0.125)},
        {"size 1e-6", 1e-6, 1e-6 * Point3(0.25, -0.5, 0.125)},
        {"size 1e6", 1e6, 1e6 * Point3(0.25, -0.5, 0.125)},
        {"size 1 at 1e6", 1.0, Point3(1e6, -7e5, 3e5)},
        {"size 1e-3 at 1e3", 1e-3, Point3(700, -300, 500)},
    };
    return list;
}

Aabb target_box(const Shape& shape, const Point3& center, double size) {
    const Aabb bounds = shape.bounds();
    if (!bounds.is_finite()) {
        return Aabb(center - Vector3::Constant(size), center + Vector3::Constant(size));
    }
    return test::enlarged(bounds, 0.05);
}

std::vector<Case> all_cases() {
    std::vector<Case> cases;
    for (const test::ExampleKind& kind : test::example_kinds()) {
        for (const Placement& placement : placements()) {
            Case own;
            own.kind = kind.name;
            own.placement = placement.name;
            std::tie(own.shape, own.reference) =
                kind.make(placement.center, placement.size, own.center);
            own.size = placement.size;
            own.target = target_box(*own.shape, own.center, own.size);
            // Shapes that cannot move (cone, torus) are the same far placement as near: skip.
            if ((own.center - placement.center).norm() <= 10 * placement.size ||
                placement.center.norm() <= 10 * placement.size) {
                cases.push_back(own);
            }

            Case instanced;
            instanced.kind = kind.name;
            instanced.placement = placement.name;
            instanced.instanced = true;
            Point3 unit_center;
            auto [unit_shape, unit_reference] = kind.make(Point3(0, 0, 0), 1.0, unit_center);
            const Transform world_from_object = Transform::translate(placement.center) *
                                                Transform::rotate(Vector3(1, 2, 3), 0.7) *
                                                Transform::scale(placement.size);
            instanced.shape = std::make_shared<Instance>(unit_shape, world_from_object);
            instanced.reference = std::make_shared<test::TransformedShape>(
                unit_reference, world_from_object.linear(), world_from_object.translation());
            instanced.center = world_from_object.apply_point(unit_center);
            instanced.size = placement.size;
            instanced.object_scale = placement.size;
            instanced.target = target_box(*instanced.shape, instanced.center, instanced.size);
            cases.push_back(instanced);
        }
    }
    return cases;
}

/// The answers of one case (or of all the cases of a kind) against the long double model, with
/// the checks a shape's own answers get beyond intersect's.
struct Tally : test::AnswerTally {
    long span_rays = 0;
    long span_failures = 0;
    long any_hit_disagreements = 0;
    /// The error as the backward error it amounts to: |t - t_ref| |d| cos / s(t), in point
    /// scales (the bound allows kRootUlps).
    double max_point_scales = 0.0;

    void add(const Tally& other) {
        AnswerTally::add(other);
        span_rays += other.span_rays;
        span_failures += other.span_failures;
        any_hit_disagreements += other.any_hit_disagreements;
        max_point_scales = std::max(max_point_scales, other.max_point_scales);
    }
    long failures() const { return disagreements() + span_failures + any_hit_disagreements; }
};

std::string describe(const Case& c, const Ray& ray) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "%s, %s%s: Ray{Point3(%.17g, %.17g, %.17g), Vector3(%.17g, %.17g, %.17g)}",
                  c.kind.c_str(), c.placement.c_str(), c.instanced ? ", instanced" : "",
                  ray.origin.x(), ray.origin.y(), ray.origin.z(), ray.direction.x(),
                  ray.direction.y(), ray.direction.z());
    return text;
}

/// Checks one ray; returns the finished hit (if any) so callers can build grazing rays from it.
std::optional<Hit> check_ray(const Case& c, const Ray& ray, Tally& tally) {
    ++tally.rays;
    const std::optional<Hit> hit = c.shape->intersect(ray);
    const bool occluded = c.shape->occluded(ray);
    if (occluded != hit.has_value()) {
        ++tally.any_hit_disagreements;
        ADD_FAILURE() << "occluded disagrees with intersect: " << describe(c, ray);
    }
    if (hit) {
        EXPECT_TRUE(std::isfinite(hit->t) && hit->t >= 0.0) << describe(c, ray);
        EXPECT_TRUE(is_finite(hit->point) && is_finite(hit->geometric_normal)) << describe(c, ray);
    }
    const Verdict verdict = judge(c, ray);
    if (verdict.ambiguous) {
        ++tally.ambiguous;
    } else if (verdict.hit) {
        ++tally.reference_hits;
        if (!hit) {
            ++tally.false_misses;
            ADD_FAILURE() << "false miss (reference t = " << static_cast<double>(verdict.t)
                          << ", cos " << static_cast<double>(verdict.cosine)
                          << "): " << describe(c, ray);
        } else {
            const double t = static_cast<double>(verdict.t);
            const double cosine = static_cast<double>(verdict.cosine);
            const double error = static_cast<double>(std::abs(hit->t - verdict.t));
            const double bound = error_bound(c, ray, t, cosine);
            tally.max_ratio = std::max(tally.max_ratio, error / bound);
            tally.max_point_scales =
                std::max(tally.max_point_scales,
                         error * ray.direction.norm() * cosine / point_scale(ray, t, c));
            // The relative error only over hits with |cos| >= 0.1 where the ray travels at
            // least as far as the coordinates of its origin and of the object are large
            // (otherwise those, not t, set the rounding, and the point scales are the measure).
            const double travel = std::abs(t) * ray.direction.norm();
            if (cosine >= 0.1 && travel >= ray.origin.norm() + c.center.norm()) {
                tally.max_relative_error = std::max(tally.max_relative_error, error / std::abs(t));
            }
            if (error > bound) {
                ++tally.wrong_t;
                ADD_FAILURE() << "t " << hit->t << " vs reference " << t << " (error " << error
                              << ", bound " << bound << ", cos " << cosine
                              << "): " << describe(c, ray);
            }
        }
    } else if (hit) {
        ++tally.false_hits;
        ADD_FAILURE() << "false hit at t = " << hit->t << ": " << describe(c, ray);
    }
    if (c.shape->is_solid() && !verdict.boundaries_ambiguous) {
        ++tally.span_rays;
        std::vector<double> ends;
        for (const Span& span : c.shape->spans(ray)) {
            if (span.enter.shape && ray.in_range(span.enter.t)) ends.push_back(span.enter.t);
            if (span.exit.shape && ray.in_range(span.exit.t)) ends.push_back(span.exit.t);
        }
        bool ok = ends.size() == verdict.boundaries.size();
        for (std::size_t i = 0; ok && i < ends.size(); ++i) {
            const double t = static_cast<double>(verdict.boundaries[i].t);
            const double cosine = static_cast<double>(verdict.boundaries[i].cosine);
            ok = std::abs(ends[i] - t) <= error_bound(c, ray, t, cosine);
        }
        if (!ok) {
            ++tally.span_failures;
            ADD_FAILURE() << "spans: " << ends.size() << " ends in range, reference "
                          << verdict.boundaries.size() << ": " << describe(c, ray);
        }
    }
    return hit;
}

/// A direction making an angle with `normal` whose cosine is `cosine`, otherwise random.
Vector3 grazing_direction(test::Random& random, const Normal3& normal, double cosine) {
    Vector3 tangent = random.unit_vector();
    tangent = (tangent - tangent.dot(normal) * normal).normalized();
    const double side = random.uniform() < 0.5 ? -1.0 : 1.0;
    return side * cosine * normal + std::sqrt(1.0 - cosine * cosine) * tangent;
}

Tally run_case(const Case& c, int rays, std::uint64_t seed) {
    test::Random random(seed);
    Tally tally;
    std::vector<Hit> surface_points;
    // Rays from 0.5 (inside or beside the object) to 1e6 sizes away toward the object.
    for (const double distance : {0.5, 2.0, 10.0, 1e3, 1e6}) {
        for (int i = 0; i < rays; ++i) {
            Ray ray;
            ray.origin = c.center + distance * c.size * random.unit_vector();
            Vector3 direction = random.in_box(c.target) - ray.origin;
            if (direction.squaredNorm() == 0.0) direction = random.unit_vector();
            ray.direction = direction.normalized() * random.uniform(0.25, 4.0);
            const std::optional<Hit> hit = check_ray(c, ray, tally);
            if (hit && distance == 10.0) surface_points.push_back(*hit);
        }
    }
    // Grazing rays through surface points, the cosine to the normal from 1e-6 to 0.1.
    for (int i = 0; i < rays && !surface_points.empty(); ++i) {
        const Hit& at = surface_points[i % surface_points.size()];
        const double cosine = std::pow(10.0, random.uniform(-6.0, -1.0));
        const Vector3 direction = grazing_direction(random, at.geometric_normal, cosine);
        const double length = random.uniform(0.25, 4.0);
        Ray ray{at.point - 2.0 * c.size * direction, direction * length};
        check_ray(c, ray, tally);
    }
    // Rays along the world axes, so direction components are exactly zero.
    for (int i = 0; i < rays / 2; ++i) {
        const int axis = i % 3;
        Vector3 direction = Vector3::Zero();
        direction[axis] = (i / 3) % 2 ? -random.uniform(0.25, 4.0) : random.uniform(0.25, 4.0);
        Ray ray;
        ray.origin = random.in_box(test::enlarged(c.target, 0.1));
        ray.origin[axis] -= 3.0 * c.size * (direction[axis] > 0 ? 1.0 : -1.0);
        ray.direction = direction;
        check_ray(c, ray, tally);
    }
    return tally;
}

TEST(ShapeAccuracy, EveryShapeAtEveryScaleAgainstLongDouble) {
    const int rays = 300 * test::stress_multiplier();
    const std::vector<Case> cases = all_cases();
    std::map<std::string, Tally> by_kind;
    std::vector<std::string> order;
    std::uint64_t seed = 7000;
    for (const Case& c : cases) {
        const Tally tally = run_case(c, rays, ++seed);
        if (test::stress_verbose()) {
            std::printf(
                "  %-24s %-18s %-9s rays %6ld hits %6ld ambiguous %5ld failures %ld"
                "  max rel err %.2e  point scales %.2f  worst/bound %.3f\n",
                c.kind.c_str(), c.placement.c_str(), c.instanced ? "instance" : "own", tally.rays,
                tally.reference_hits, tally.ambiguous, tally.failures(), tally.max_relative_error,
                tally.max_point_scales, tally.max_ratio);
        }
        if (!by_kind.count(c.kind)) order.push_back(c.kind);
        by_kind[c.kind].add(tally);
    }
    Tally total;
    std::printf(
        "\n  | shape | rays | clear hits | ambiguous | false hits | false misses | wrong t"
        " | span rays / failures | max rel t error (cos >= 0.1, |t d| >= |o| + |c|)"
        " | max error (point scales) | worst error / bound |\n");
    for (const std::string& kind : order) {
        const Tally& t = by_kind[kind];
        std::printf(
            "  | %s | %ld | %ld | %ld | %ld | %ld | %ld | %ld / %ld | %.1e | %.2f | %.3f |\n",
            kind.c_str(), t.rays, t.reference_hits, t.ambiguous, t.false_hits, t.false_misses,
            t.wrong_t, t.span_rays, t.span_failures, t.max_relative_error, t.max_point_scales,
            t.max_ratio);
        total.add(t);
        EXPECT_EQ(t.failures(), 0) << kind;
        test::summarize(kind, t.rays, t.failures(), t.max_relative_error, "rel t");
        // Rays in the ambiguity bands are few except for the grazing set (1/7 of the rays);
        // thin tori are hit by few of the rays aimed at their bounds.
        EXPECT_LT(t.ambiguous, t.rays / 7) << kind;
        EXPECT_GT(t.reference_hits, t.rays / 20) << kind;
    }
    std::printf(
        "  | all (%zu cases) | %ld | %ld | %ld | %ld | %ld | %ld | %ld / %ld | %.1e | %.2f | %.3f "
        "|\n\n",
        cases.size(), total.rays, total.reference_hits, total.ambiguous, total.false_hits,
        total.false_misses, total.wrong_t, total.span_rays, total.span_failures,
        total.max_relative_error, total.max_point_scales, total.max_ratio);
}

/// A part object family: the object with an angle range, and a surface point (object space) at
/// a given angle of that range, the other parameters random.
struct PartFamily {
    std::string name;
    std::function<ShapePointer(double min, double max)> make;
    std::function<Point3(double angle, test::Random& random)> point_at;
};

constexpr double kPartMajor = 1.0;
constexpr double kPartMinor = 0.25;

std::vector<PartFamily> part_families() {
    return std::vector<PartFamily>{
        {"part_sphere azimuth",
         [](double min, double max) {
             return std::make_shared<PartSphere>(Point3(0, 0, 0), 1.0, min, max, 0.3, 2.5);
         },
         [](double phi, test::Random& random) {
             const double theta = random.uniform(0.35, 2.45);
             return Point3(std::sin(theta) * std::sin(phi), std::cos(theta),
                           std::sin(theta) * std::cos(phi));
         }},
        {"part_cylinder azimuth",
         [](double min, double max) {
             return std::make_shared<PartCylinder>(1.0, -1.0, 1.0, min, max);
         },
         [](double phi, test::Random& random) {
             return Point3(std::sin(phi), random.uniform(-0.9, 0.9), std::cos(phi));
         }},
        {"annulus azimuth",
         [](double min, double max) {
             return std::make_shared<Annulus>(Point3(0, 0, 0), Normal3(0, 1, 0), 0.3, 1.0, min,
                                              max);
         },
         [](double phi, test::Random& random) {
             const double rho = random.uniform(0.35, 0.95);
             return Point3(rho * std::sin(phi), 0.0, rho * std::cos(phi));
         }},
        {"part_torus phi",
         [](double min, double max) {
             return std::make_shared<PartTorus>(kPartMajor, kPartMinor, min, max, 0.0, kTwoPi);
         },
         [](double phi, test::Random& random) {
             const double theta = random.uniform(0.0, kTwoPi);
             const double rho = kPartMajor + kPartMinor * std::cos(theta);
             return Point3(rho * std::sin(phi), kPartMinor * std::sin(theta), rho * std::cos(phi));
         }},
        {"part_torus theta",
         [](double min, double max) {
             return std::make_shared<PartTorus>(kPartMajor, kPartMinor, 0.0, kTwoPi, min, max);
         },
         [](double theta, test::Random& random) {
             const double phi = random.uniform(0.0, kTwoPi);
             const double rho = kPartMajor + kPartMinor * std::cos(theta);
             return Point3(rho * std::sin(phi), kPartMinor * std::sin(theta), rho * std::cos(phi));
         }},
    };
}

TEST(ShapeAccuracy, ComplementaryPartsLeaveNoCrackAtSeamsAndLimits) {
    // Two parts with complementary ranges [a, b] and [b, a + 2 pi] cover the full surface: at
    // every ray, the nearer of their hits is the full-range object's hit, bit for bit (the
    // same roots, only filtered), including rays aimed exactly at the limits a and b and at
    // the seam 0 = 2 pi, and a few ulps of angle beside them. Placed bare and by an instance
    // at 1e6 scale a million units away.
    const double ranges[][2] = {{0.0, kPi}, {kPi / 2, 3 * kPi / 2}, {1.0, 1.001}, {2.5, 6.0}};
    const Transform far = Transform::translate(Vector3(1e6, -2e6, 5e5)) *
                          Transform::rotate(Vector3(-1, 3, 2), 2.1) * Transform::scale(1e6);
    test::Random random(31);
    const int rays = 500 * test::stress_multiplier();
    std::printf("  | family | rays | full hits | hits at limits seen by both parts |\n");
    for (const PartFamily& family : part_families()) {
        const long failed_before = test::failed_assertions();
        long checked = 0, full_hits = 0, both = 0;
        for (const auto& range : ranges) {
            const double a = range[0], b = range[1];
            for (const bool instanced : {false, true}) {
                auto place = [&](ShapePointer shape) -> ShapePointer {
                    return instanced ? std::make_shared<Instance>(shape, far) : shape;
                };
                const ShapePointer full = place(family.make(0.0, kTwoPi));
                const ShapePointer first = place(family.make(a, b));
                const ShapePointer second = place(family.make(b, a + kTwoPi));
                for (int i = 0; i < rays; ++i) {
                    const double limits[] = {a, b, 0.0};
                    double angle = limits[i % 3];
                    const int nudge = (i / 3) % 5 - 2;  // -2 .. 2 ulps of the angle
                    for (int k = 0; k < std::abs(nudge); ++k) {
                        angle = std::nextafter(angle, nudge > 0 ? 10.0 : -10.0);
                    }
                    Point3 target = family.point_at(angle, random);
                    Ray ray;
                    ray.origin = random.unit_vector() * random.uniform(2.0, 10.0);
                    ray.direction = (target - ray.origin) * random.uniform(0.25, 4.0);
                    if (instanced) ray = far.apply(ray);
                    const std::optional<Hit> whole = full->intersect(ray);
                    const std::optional<Hit> hit_a = first->intersect(ray);
                    const std::optional<Hit> hit_b = second->intersect(ray);
                    ++checked;
                    const std::string where = family.name + " range [" + std::to_string(a) + ", " +
                                              std::to_string(b) + "] ray " + std::to_string(i) +
                                              (instanced ? " instanced" : "");
                    if (!whole) {
                        EXPECT_FALSE(hit_a || hit_b) << where;
                        continue;
                    }
                    ++full_hits;
                    ASSERT_TRUE(hit_a || hit_b) << "crack: " << where;
                    const double nearest =
                        std::min(hit_a ? hit_a->t : kInfinity, hit_b ? hit_b->t : kInfinity);
                    EXPECT_EQ(nearest, whole->t) << where;
                    if (hit_a && hit_b && hit_a->t == hit_b->t) ++both;
                }
            }
        }
        std::printf("  | %s | %ld | %ld | %ld |\n", family.name.c_str(), checked, full_hits, both);
        EXPECT_GT(full_hits, checked / 2) << family.name;
        test::summarize(family.name + " seams", checked, test::failed_assertions() - failed_before);
    }
}

TEST(ShapeAccuracy, TorusAlongAndBesideItsAxis) {
    // Along the y axis a ray passes through the hole: a miss at every scale and thinness, from
    // near and from 1e6 sizes away. Parallel to the axis through the middle of the tube
    // (rho = R + r / 2) it crosses at y = +-(sqrt 3 / 2) r, where |cos| = sqrt 3 / 2: t is
    // within kRootUlps point scales over cos (the bound of the table above).
    for (const double scale : {1e-6, 1.0, 1e6}) {
        for (const double ratio : {0.25, 1e-2, 1e-3}) {
            const double major = scale, minor = ratio * scale;
            const Torus torus(major, minor);
            for (const double distance : {10.0, 1e6}) {
                const double height = distance * major;
                for (const double sign : {1.0, -1.0}) {
                    const Ray axis{Point3(0, sign * height, 0), Vector3(0, -sign * 0.5, 0)};
                    EXPECT_FALSE(torus.intersect(axis)) << scale << " " << ratio;
                    EXPECT_FALSE(torus.occluded(axis));
                    EXPECT_TRUE(torus.spans(axis).empty());
                    const double rho = major + 0.5 * minor;
                    const Ray beside{Point3(rho * 0.6, sign * height, rho * 0.8),
                                     Vector3(0, -sign * 2.0, 0)};
                    const std::optional<Hit> hit = torus.intersect(beside);
                    ASSERT_TRUE(hit) << scale << " " << ratio << " " << distance;
                    const long double expected =
                        (static_cast<long double>(height) -
                         std::sqrt(3.0L) / 2 * static_cast<long double>(minor)) /
                        2.0L;
                    const double s = kUnitRoundoff * (beside.origin.norm() + 2 * height + major);
                    const double bound =
                        kRootUlps * s / (2.0 * std::sqrt(3.0) / 2) + 4 * kUnitRoundoff * height;
                    EXPECT_LE(static_cast<double>(std::abs(hit->t - expected)), bound)
                        << scale << " " << ratio << " " << distance;
                    const SpanList spans = torus.spans(beside);
                    ASSERT_EQ(spans.size(), 1u);
                    EXPECT_EQ(spans[0].enter.t, hit->t);
                    EXPECT_NEAR(spans[0].exit.t - spans[0].enter.t, std::sqrt(3.0) * minor / 2.0,
                                2 * bound);
                }
            }
        }
    }
    // 3 scales x 3 thinnesses x 2 distances x 2 sides x 2 rays.
    test::summarize("torus along and beside its axis", 72, test::failed_assertions());
}

}  // namespace
}  // namespace csgrt
