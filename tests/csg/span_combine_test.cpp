#include "csgrt/csg/span_combine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "csgrt/core/sphere.h"
#include "support/random.h"

namespace csgrt {
namespace {

// Span lists written by hand along the x axis from the origin, so t is the x coordinate and the
// coincidence tolerance is kSpanCoincidenceUlps u |t|. The spheres only serve as distinct
// surface tags in the records.
const Ray kRay{Point3(0, 0, 0), Vector3(1, 0, 0)};
const Sphere kSurfaceA(Point3(0, 0, 0), 1.0);
const Sphere kSurfaceB(Point3(0, 0, 0), 2.0);

HitRecord end(double t, const Shape* shape, std::uint32_t primitive = 0) {
    return HitRecord{.t = t, .shape = shape, .primitive = primitive};
}

SpanList spans_of(const Shape* shape, std::initializer_list<std::pair<double, double>> ranges) {
    SpanList spans;
    std::uint32_t index = 0;
    for (const auto& [enter, exit] : ranges) {
        spans.push_back(Span{end(enter, shape, index), end(exit, shape, index + 1)});
        index += 2;
    }
    return spans;
}

SpanList combine(BooleanOperation operation, const SpanList& a, const SpanList& b) {
    SpanList result;
    combine_spans(operation, a, b, kRay, result);
    return result;
}

void expect_span(const Span& span, double enter, const Shape* enter_shape, double exit,
                 const Shape* exit_shape) {
    EXPECT_EQ(span.enter.t, enter);
    EXPECT_EQ(span.enter.shape, enter_shape);
    EXPECT_EQ(span.exit.t, exit);
    EXPECT_EQ(span.exit.shape, exit_shape);
}

constexpr auto kUnion = BooleanOperation::Union;
constexpr auto kIntersection = BooleanOperation::Intersection;
constexpr auto kDifference = BooleanOperation::Difference;

TEST(SpanCombine, UnionMergesOverlappingAndTouchingSpans) {
    const SpanList a = spans_of(&kSurfaceA, {{1, 3}, {7, 8}});
    const SpanList b = spans_of(&kSurfaceB, {{2, 5}, {8, 9}});
    const SpanList result = combine(kUnion, a, b);
    ASSERT_EQ(result.size(), 2u);
    expect_span(result[0], 1, &kSurfaceA, 5, &kSurfaceB);
    // [7, 8] and [8, 9] touch: one span, no internal surface at 8.
    expect_span(result[1], 7, &kSurfaceA, 9, &kSurfaceB);
}

TEST(SpanCombine, IntersectionKeepsTheOverlapAndDropsTouchingSpans) {
    const SpanList a = spans_of(&kSurfaceA, {{1, 3}, {6, 8}});
    const SpanList b = spans_of(&kSurfaceB, {{2, 6}});
    const SpanList result = combine(kIntersection, a, b);
    ASSERT_EQ(result.size(), 1u);  // [6, 6] is a touch of two solids: empty when regularised
    expect_span(result[0], 2, &kSurfaceB, 3, &kSurfaceA);
    HitRecord first;
    EXPECT_FALSE(first_combined_boundary(kIntersection, spans_of(&kSurfaceA, {{1, 2}}),
                                         spans_of(&kSurfaceB, {{2, 3}}), kRay, first));
}

TEST(SpanCombine, DifferenceFlipsTheSubtractedSurfacesAndTogglesTwice) {
    const SpanList a = spans_of(&kSurfaceA, {{1, 5}});
    SpanList b = spans_of(&kSurfaceB, {{2, 3}});
    SpanList result = combine(kDifference, a, b);
    ASSERT_EQ(result.size(), 2u);
    expect_span(result[0], 1, &kSurfaceA, 2, &kSurfaceB);
    expect_span(result[1], 3, &kSurfaceB, 5, &kSurfaceA);
    EXPECT_FALSE(result[0].enter.flip_normal);
    EXPECT_TRUE(result[0].exit.flip_normal);
    EXPECT_TRUE(result[1].enter.flip_normal);
    EXPECT_FALSE(result[1].exit.flip_normal);
    EXPECT_EQ(result[0].exit.primitive, 0u);  // B's enter record, kept whole
    // A surface already flipped by an inner difference is flipped back.
    b[0].enter.flip_normal = true;
    result = combine(kDifference, a, b);
    EXPECT_FALSE(result[0].exit.flip_normal);
}

TEST(SpanCombine, AnOperandWithItselfFollowsTheSetIdentities) {
    const SpanList a = spans_of(&kSurfaceA, {{1, 2}, {3, 4}, {6, 6}});
    for (BooleanOperation operation : {kUnion, kIntersection}) {
        const SpanList result = combine(operation, a, a);
        // The tangent at 6 survives the union only: an intersection keeps a tangent only
        // strictly inside the other operand (docs/csg.md).
        const std::size_t expected = operation == kUnion ? a.size() : a.size() - 1;
        ASSERT_EQ(result.size(), expected);
        for (std::size_t i = 0; i < expected; ++i) {
            expect_span(result[i], a[i].enter.t, &kSurfaceA, a[i].exit.t, &kSurfaceA);
            EXPECT_FALSE(result[i].enter.flip_normal || result[i].exit.flip_normal);
        }
    }
    EXPECT_TRUE(combine(kDifference, a, a).empty());
    HitRecord first;
    EXPECT_FALSE(first_combined_boundary(kDifference, a, a, kRay, first));
}

TEST(SpanCombine, EndsWithinTheToleranceAreOneSurface) {
    // A second copy of the surface, off by a few ulps as a different computation of the same
    // sphere would be: A - A' is empty, A n A' is A (first operand preferred at a tie).
    const double ulp = kUnitRoundoff;
    const SpanList a = spans_of(&kSurfaceA, {{1, 2}});
    const SpanList nearly_a = spans_of(&kSurfaceB, {{1 + 8 * ulp, 2 - 16 * ulp}});
    EXPECT_TRUE(combine(kDifference, a, nearly_a).empty());
    EXPECT_TRUE(combine(kDifference, nearly_a, a).empty());
    SpanList result = combine(kIntersection, a, nearly_a);
    ASSERT_EQ(result.size(), 1u);
    expect_span(result[0], 1, &kSurfaceA, 2, &kSurfaceA);
    // A gap just above the tolerance is real: two slivers remain.
    const double gap = 2.0 * span_coincidence_tolerance(kRay, 2.0);
    result = combine(kDifference, a, spans_of(&kSurfaceB, {{1 + gap, 2 - gap}}));
    ASSERT_EQ(result.size(), 2u);
    EXPECT_EQ(result[0].exit.t, 1 + gap);
    EXPECT_TRUE(result[0].exit.flip_normal);
}

TEST(SpanCombine, ToleranceScalesWithTheCoordinates) {
    EXPECT_EQ(span_coincidence_tolerance(kRay, kInfinity), 0.0);
    EXPECT_DOUBLE_EQ(span_coincidence_tolerance(kRay, 4.0),
                     kSpanCoincidenceUlps * kUnitRoundoff * 4);
    // An origin 1000 direction lengths away rounds like t = 1000.
    const Ray far{Point3(0, -2000, 0), Vector3(0, 2, 0)};
    EXPECT_DOUBLE_EQ(span_coincidence_tolerance(far, 0.0),
                     kSpanCoincidenceUlps * kUnitRoundoff * 1000);
}

TEST(SpanCombine, ZeroLengthSpansNeverHitInsideTheResult) {
    const SpanList wide = spans_of(&kSurfaceB, {{1, 3}});
    const SpanList tangent_inside = spans_of(&kSurfaceA, {{2, 2}});
    const SpanList tangent_outside = spans_of(&kSurfaceA, {{5, 5}});
    const SpanList tangent_on_end = spans_of(&kSurfaceA, {{3, 3}});
    // Union: a tangent inside the other solid vanishes; an isolated one is a touching point.
    SpanList result = combine(kUnion, tangent_inside, wide);
    ASSERT_EQ(result.size(), 1u);
    expect_span(result[0], 1, &kSurfaceB, 3, &kSurfaceB);
    result = combine(kUnion, tangent_outside, wide);
    ASSERT_EQ(result.size(), 2u);
    expect_span(result[1], 5, &kSurfaceA, 5, &kSurfaceA);
    // Intersection: the tangent point lies on the result's surface strictly inside the other
    // solid; at the other's end it is where two solids touch, which is no intersection.
    result = combine(kIntersection, tangent_inside, wide);
    ASSERT_EQ(result.size(), 1u);
    expect_span(result[0], 2, &kSurfaceA, 2, &kSurfaceA);
    EXPECT_TRUE(combine(kIntersection, tangent_on_end, wide).empty());
    EXPECT_TRUE(combine(kIntersection, tangent_outside, wide).empty());
    EXPECT_TRUE(combine(kIntersection, tangent_inside, tangent_inside).empty());
    // Difference: subtracting a tangent removes nothing; a tangent on the subtracted solid's
    // closed set is removed.
    result = combine(kDifference, wide, tangent_inside);
    ASSERT_EQ(result.size(), 1u);
    expect_span(result[0], 1, &kSurfaceB, 3, &kSurfaceB);
    EXPECT_TRUE(combine(kDifference, tangent_inside, wide).empty());
    EXPECT_TRUE(combine(kDifference, tangent_on_end, wide).empty());
    EXPECT_EQ(combine(kDifference, tangent_outside, wide).size(), 1u);
    EXPECT_TRUE(combine(kDifference, tangent_inside, tangent_inside).empty());
    // The first hit of a ray starting inside the union is the far side, not the tangent.
    HitRecord first;
    Ray inside = kRay;
    inside.t_min = 1.5;
    ASSERT_TRUE(first_combined_boundary(kUnion, tangent_inside, wide, inside, first));
    EXPECT_EQ(first.t, 3.0);
}

TEST(SpanCombine, UnboundedEndsAreNeverHits) {
    const SpanList everything{Span{HitRecord{.t = -kInfinity}, HitRecord{.t = kInfinity}}};
    const SpanList b = spans_of(&kSurfaceB, {{1, 2}});
    const SpanList result = combine(kDifference, everything, b);
    ASSERT_EQ(result.size(), 2u);
    expect_span(result[0], -kInfinity, nullptr, 1, &kSurfaceB);
    expect_span(result[1], 2, &kSurfaceB, kInfinity, nullptr);
    HitRecord first;
    ASSERT_TRUE(first_combined_boundary(kDifference, everything, b, kRay, first));
    EXPECT_EQ(first.t, 1.0);
    EXPECT_TRUE(first.flip_normal);
    Ray beyond = kRay;
    beyond.t_min = 3.0;
    EXPECT_FALSE(first_combined_boundary(kDifference, everything, b, beyond, first));
    EXPECT_FALSE(first_combined_boundary(kUnion, everything, b, kRay, first));
}

TEST(SpanCombine, FirstBoundaryHonoursTheClosedIntervalAtBothEnds) {
    const SpanList a = spans_of(&kSurfaceA, {{1, 3}});
    const SpanList b = spans_of(&kSurfaceB, {{2, 5}});
    HitRecord first;
    Ray ray = kRay;
    ray.t_min = 1.0;
    ASSERT_TRUE(first_combined_boundary(kUnion, a, b, ray, first));
    EXPECT_EQ(first.t, 1.0);
    ray.t_min = std::nextafter(1.0, 2.0);
    ASSERT_TRUE(first_combined_boundary(kUnion, a, b, ray, first));
    EXPECT_EQ(first.t, 5.0);
    ray.t_max = 5.0;
    EXPECT_TRUE(first_combined_boundary(kUnion, a, b, ray, first));
    ray.t_max = std::nextafter(5.0, 0.0);
    first.t = -7.0;
    EXPECT_FALSE(first_combined_boundary(kUnion, a, b, ray, first));
    EXPECT_EQ(first.t, -7.0);  // untouched on a miss
}

TEST(SpanCombine, NanEndsTerminate) {
    const double nan = std::nan("");
    const SpanList a = spans_of(&kSurfaceA, {{nan, 1}, {2, nan}, {nan, nan}});
    const SpanList b = spans_of(&kSurfaceB, {{0, nan}, {nan, 3}});
    for (BooleanOperation operation : {kUnion, kIntersection, kDifference}) {
        SpanList result;
        combine_spans(operation, a, b, kRay, result);
        combine_spans(operation, b, a, kRay, result);
        HitRecord first;
        first_combined_boundary(operation, a, b, kRay, first);
        EXPECT_LE(result.size(), a.size() + b.size());
    }
}

// The declarative statement of the rules on lists whose ends lie on integers (exact ties, gaps
// far above the tolerance): each open stretch between consecutive integers is classified by the
// operation; a zero-length span of an operand at x survives, outside the result's stretches,
// as the rules of docs/csg.md say.
struct Model {
    const SpanList& spans;
    bool inside(double a, double b) const {  // the open stretch (a, b)
        for (const Span& s : spans)
            if (s.enter.t <= a && b <= s.exit.t && s.enter.t < s.exit.t) return true;
        return false;
    }
    bool closed(double x) const {
        for (const Span& s : spans)
            if (s.enter.t <= x && x <= s.exit.t) return true;
        return false;
    }
    bool point(double x) const {
        bool zero_length = false;
        for (const Span& s : spans) zero_length |= s.enter.t == x && s.exit.t == x;
        return zero_length && !inside(x - 1, x) && !inside(x, x + 1);
    }
};

bool apply(BooleanOperation operation, bool a, bool b) {
    return operation == kUnion ? a || b : operation == kIntersection ? a && b : a && !b;
}

SpanList random_integer_spans(test::Random& random, const Shape* shape) {
    SpanList spans;
    int t = random.integer(-1, 3);
    const int count = random.integer(0, 4);
    for (int i = 0; i < count; ++i) {
        const int enter = t;
        const int exit = enter + random.integer(0, 3);  // 0: a tangent
        spans.push_back(Span{end(enter, shape, 2 * i), end(exit, shape, 2 * i + 1)});
        t = exit + random.integer(1, 3);
    }
    return spans;
}

TEST(SpanCombine, RandomIntegerListsFollowTheDeclarativeRules) {
    test::Random random(31);
    int points = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const SpanList a = random_integer_spans(random, &kSurfaceA);
        const SpanList b = random_integer_spans(random, &kSurfaceB);
        const auto operation = static_cast<BooleanOperation>(random.integer(0, 2));
        const Model model_a{a}, model_b{b};
        const SpanList result = combine(operation, a, b);
        const Model model_result{result};
        SCOPED_TRACE(::testing::Message() << "trial " << trial);
        for (int x = -3; x <= 20; ++x) {
            // Stretch membership, and ends only where the classification changes.
            const bool expected =
                apply(operation, model_a.inside(x, x + 1), model_b.inside(x, x + 1));
            ASSERT_EQ(model_result.inside(x, x + 1), expected) << "stretch " << x;
            bool expected_point = false;
            const bool b_closed = model_b.closed(x);
            const bool a_around = model_a.inside(x - 1, x) && model_a.inside(x, x + 1);
            const bool b_around = model_b.inside(x - 1, x) && model_b.inside(x, x + 1);
            if (operation == kUnion) expected_point = model_a.point(x) || model_b.point(x);
            if (operation == kIntersection)
                expected_point = (model_a.point(x) && b_around) || (model_b.point(x) && a_around);
            if (operation == kDifference) expected_point = model_a.point(x) && !b_closed;
            expected_point &= !model_result.inside(x - 1, x) && !model_result.inside(x, x + 1);
            ASSERT_EQ(model_result.point(x), expected_point) << "point " << x;
            points += expected_point;
        }
        // Sorted, separated by real gaps, each end an operand's record of the same t, flipped
        // exactly when it comes from the subtracted operand.
        for (std::size_t i = 0; i < result.size(); ++i) {
            ASSERT_LE(result[i].enter.t, result[i].exit.t);
            if (i > 0) {
                ASSERT_LT(result[i - 1].exit.t, result[i].enter.t);
            }
            for (const HitRecord* record : {&result[i].enter, &result[i].exit}) {
                const bool from_b = record->shape == &kSurfaceB;
                ASSERT_EQ(record->flip_normal, from_b && operation == kDifference);
                const SpanList& source = from_b ? b : a;
                const Span& span = source[record->primitive / 2];
                ASSERT_EQ(record->t, record->primitive % 2 ? span.exit.t : span.enter.t);
            }
        }
        // The first end in a random interval is the first listed end in it.
        Ray ray = kRay;
        ray.t_min = random.integer(-2, 12) + (random.integer(0, 1) ? 0.0 : 0.5);
        ray.t_max = ray.t_min + random.integer(0, 8);
        double expected_first = kInfinity;
        for (const Span& span : result)
            for (const HitRecord* record : {&span.enter, &span.exit})
                if (ray.in_range(record->t)) expected_first = std::min(expected_first, record->t);
        HitRecord first;
        const bool found = first_combined_boundary(operation, a, b, ray, first);
        ASSERT_EQ(found, expected_first != kInfinity);
        if (found) {
            ASSERT_EQ(first.t, expected_first);
        }
    }
    EXPECT_GT(points, 1000);
}

}  // namespace
}  // namespace csgrt
