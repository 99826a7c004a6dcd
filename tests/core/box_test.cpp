#include "csgrt/core/box.h"

#include <gtest/gtest.h>

// shape_properties.h uses cross() but does not include the Eigen module that defines it.
#include <Eigen/Geometry>

#include "csgrt/core/error.h"
#include "support/error_of.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using test::error_of;

const Box kCube(Point3(-1, -1, -1), Point3(1, 1, 1));

// Faces: 0..5 = -x, +x, -y, +y, -z, +z.
constexpr std::uint32_t kMinusX = 0, kPlusX = 1, kPlusY = 3, kMinusY = 2;

TEST(Box, AnalyticHitFromOutside) {
    const Ray ray{Point3(-5, 0.5, 0.25), Vector3(2, 0, 0)};
    const std::optional<Hit> hit = kCube.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 2.0);
    EXPECT_EQ(hit->point, Point3(-1, 0.5, 0.25));
    EXPECT_EQ(hit->geometric_normal, Normal3(-1, 0, 0));
    EXPECT_TRUE(hit->front_face);
    EXPECT_EQ(hit->primitive_id, kMinusX);
    EXPECT_EQ(hit->uv, Vector2(0.75, 0.625));  // x face: (y, z) scaled to [0, 1]
    const SpanList spans = kCube.spans(ray);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 2.0);
    EXPECT_EQ(spans[0].exit.t, 3.0);
    EXPECT_EQ(spans[0].enter.primitive, kMinusX);
    EXPECT_EQ(spans[0].exit.primitive, kPlusX);
}

TEST(Box, EveryFaceHasItsOutwardNormal) {
    for (int axis = 0; axis < 3; ++axis) {
        for (const double side : {-1.0, 1.0}) {
            Point3 origin(0.1, 0.2, 0.3);
            origin[axis] = 4 * side;
            Vector3 direction = Vector3::Zero();
            direction[axis] = -side * 0.5;
            const std::optional<Hit> hit = kCube.intersect(Ray{origin, direction});
            ASSERT_TRUE(hit);
            EXPECT_EQ(hit->t, 6.0);
            Normal3 expected = Normal3::Zero();
            expected[axis] = side;
            EXPECT_EQ(hit->geometric_normal, expected);
            EXPECT_EQ(hit->primitive_id, std::uint32_t(2 * axis + (side > 0 ? 1 : 0)));
            EXPECT_TRUE(hit->front_face);
        }
    }
}

TEST(Box, FromInsideHitsTheExitFaceFromBehind) {
    const Ray ray{Point3(0, 0, 0), Vector3(0, 0.5, 0)};
    ASSERT_TRUE(test::expect_hit_from_behind(kCube, ray, 2.0, Normal3(0, 1, 0)));
    const SpanList spans = kCube.spans(ray);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, -2.0);  // the line's interval, not clipped to the ray
    EXPECT_EQ(spans[0].enter.primitive, kMinusY);
    EXPECT_EQ(spans[0].exit.primitive, kPlusY);
    EXPECT_TRUE(kCube.contains(Point3(0, 0, 0)));
}

TEST(Box, MissesAndPointingAway) {
    EXPECT_FALSE(kCube.intersect(Ray{Point3(-5, 1.5, 0), Vector3(1, 0, 0)}));
    EXPECT_FALSE(kCube.intersect(Ray{Point3(-5, 0, 0), Vector3(-1, 0, 0)}));
    EXPECT_FALSE(kCube.occluded(Ray{Point3(-5, 0, 0), Vector3(-1, 0, 0)}));
    // Past a corner diagonally: x enters at 4, y leaves at 3.9.
    EXPECT_FALSE(kCube.intersect(Ray{Point3(-5, -2.9, 0), Vector3(1, 1, 0)}));
    EXPECT_TRUE(kCube.spans(Ray{Point3(-5, -2.9, 0), Vector3(1, 1, 0)}).empty());
}

TEST(Box, TouchingAnEdgeOrACornerIsAZeroLengthSpan) {
    // x slab [2, 4], y slab [0, 2]: the line touches the edge x = -1, y = 1 at t = 2.
    const Ray edge{Point3(-3, -1, 0), Vector3(1, 1, 0)};
    const std::optional<Hit> hit = kCube.intersect(edge);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 2.0);
    EXPECT_EQ(hit->point, Point3(-1, 1, 0));
    EXPECT_EQ(hit->primitive_id, kMinusX);  // a tie goes to the lower axis
    EXPECT_TRUE(kCube.occluded(edge));
    SpanList spans = kCube.spans(edge);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 2.0);
    EXPECT_EQ(spans[0].exit.t, 2.0);
    EXPECT_EQ(spans[0].exit.primitive, kPlusY);
    // The corner (1, 1, 1) alone, by a ray in the face plane z = 1.
    const Ray corner{Point3(0, 2, 1), Vector3(1, -1, 0)};
    ASSERT_TRUE(kCube.intersect(corner));
    EXPECT_EQ(kCube.intersect(corner)->t, 1.0);
    spans = kCube.spans(corner);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, spans[0].exit.t);
}

TEST(Box, RayInAFacePlaneGrazesConsistently) {
    // In the plane y = 1 across the +y face: the closed box contains the segment, so all three
    // queries see it; the hit is where it enters, on the edge with the -x face.
    const Ray along_face{Point3(-5, 1, 0), Vector3(1, 0, 0)};
    const std::optional<Hit> hit = kCube.intersect(along_face);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->primitive_id, kMinusX);
    EXPECT_TRUE(kCube.occluded(along_face));
    const SpanList spans = kCube.spans(along_face);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 4.0);
    EXPECT_EQ(spans[0].exit.t, 6.0);
    EXPECT_TRUE(kCube.contains(along_face.at(5.0)));  // consistent with the span
    // In the face plane but beside the face: nothing.
    const Ray beside{Point3(-5, 1, 3), Vector3(1, 0, 0)};
    EXPECT_FALSE(kCube.intersect(beside));
    EXPECT_FALSE(kCube.occluded(beside));
    EXPECT_TRUE(kCube.spans(beside).empty());
}

TEST(Box, RaysParallelToAFace) {
    const double above = next_up(1.0), below = next_down(1.0);
    EXPECT_FALSE(kCube.intersect(Ray{Point3(-5, above, 0), Vector3(1, 0, 0)}));
    EXPECT_TRUE(kCube.spans(Ray{Point3(-5, above, 0), Vector3(1, 0, 0)}).empty());
    EXPECT_TRUE(kCube.intersect(Ray{Point3(-5, below, 0), Vector3(1, 0, 0)}));
    // Along an axis from inside, with two zero direction components.
    const std::optional<Hit> hit = kCube.intersect(Ray{Point3(0.5, 0.5, 0.5), Vector3(0, 0, -4)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 0.375);
    EXPECT_EQ(hit->geometric_normal, Normal3(0, 0, -1));
}

TEST(Box, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};  // enters at 4, leaves at 6
    Ray clipped = ray;
    clipped.t_max = next_down(4.0);
    EXPECT_FALSE(kCube.intersect(clipped));
    EXPECT_FALSE(kCube.occluded(clipped));
    EXPECT_TRUE(kCube.spans(clipped).empty());
    clipped.t_max = 4.0;
    ASSERT_TRUE(kCube.intersect(clipped));
    EXPECT_EQ(kCube.intersect(clipped)->t, 4.0);
    EXPECT_EQ(kCube.spans(clipped).size(), 1u);
    clipped = ray;
    clipped.t_min = next_up(4.0);  // past the entry: the exit face
    ASSERT_TRUE(kCube.intersect(clipped));
    EXPECT_EQ(kCube.intersect(clipped)->t, 6.0);
    EXPECT_EQ(kCube.intersect(clipped)->primitive_id, kPlusX);
    clipped.t_min = 6.0;
    EXPECT_TRUE(kCube.intersect(clipped));
    clipped.t_min = next_up(6.0);
    EXPECT_FALSE(kCube.intersect(clipped));
    EXPECT_FALSE(kCube.occluded(clipped));
    EXPECT_TRUE(kCube.spans(clipped).empty());
}

TEST(Box, InvalidRaysNeverHit) {
    const double nan = std::nan("");
    test::expect_invalid_rays_miss(kCube, Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)});
    // The raw queries on a NaN direction must not report a usable hit either.
    HitRecord record;
    QueryScratch scratch;
    EXPECT_FALSE(kCube.nearest_hit(Ray{Point3(-5, 0, 0), Vector3(nan, nan, nan)}, record, scratch));
}

TEST(Box, RejectsBadParametersNamingThem) {
    EXPECT_NE(error_of([] { Box(Point3(0, 0, 0), Point3(1, 0, 1)); }).find("Box: upper"),
              std::string::npos);
    EXPECT_NE(error_of([] { Box(Point3(0, 0, 0), Point3(1, -1, 1)); }).find("Box: upper"),
              std::string::npos);
    EXPECT_NE(error_of([] { Box(Point3(std::nan(""), 0, 0), Point3(1, 1, 1)); }).find("Box: lower"),
              std::string::npos);
    EXPECT_NE(error_of([] { Box(Point3(0, 0, 0), Point3(1, kInfinity, 1)); }).find("Box: upper"),
              std::string::npos);
}

TEST(Box, ContainsIsClosed) {
    EXPECT_TRUE(kCube.contains(Point3(1, 1, 1)));
    EXPECT_TRUE(kCube.contains(Point3(-1, 0, 0.5)));
    EXPECT_FALSE(kCube.contains(Point3(next_up(1.0), 0, 0)));
    EXPECT_FALSE(kCube.contains(Point3(0, std::nan(""), 0)));
}

TEST(Box, MatchesLongDoubleFaceByFaceCrossings) {
    // The independent answer: each face as a bounded plane, crossed in long double; the
    // nearest crossing in range is the hit.
    test::Random random(71);
    int compared = 0, hits = 0;
    for (int i = 0; i < 50000; ++i) {
        const Point3 a = random.in_box(Aabb(Point3(-5, -5, -5), Point3(5, 5, 5)));
        const Point3 b = random.in_box(Aabb(Point3(-5, -5, -5), Point3(5, 5, 5)));
        const Box box(a.cwiseMin(b), a.cwiseMax(b));
        Ray ray = test::ray_toward(random, box.bounds(), i);
        long double best = kInfinity;
        int best_face = -1;
        bool ambiguous = false;
        const long double size = (box.upper() - box.lower()).norm();
        for (int face = 0; face < 6; ++face) {
            const int axis = face / 2;
            const long double plane = face % 2 ? box.upper()[axis] : box.lower()[axis];
            if (ray.direction[axis] == 0) continue;
            const long double t = (plane - ray.origin[axis]) / (long double)ray.direction[axis];
            bool inside = true;
            for (int other = 0; other < 3; ++other) {
                if (other == axis) continue;
                const long double x = ray.origin[other] + t * (long double)ray.direction[other];
                const long double margin = std::min(x - box.lower()[other], box.upper()[other] - x);
                if (std::abs(margin) < 1e-9L * size) ambiguous = true;  // too near an edge
                if (margin < 0) inside = false;
            }
            if (std::abs(t) * ray.direction.norm() < 1e-9L * size) ambiguous = true;
            if (inside && t >= 0 && t < best) {
                best = t;
                best_face = face;
            }
        }
        if (ambiguous) continue;
        ++compared;
        const std::optional<Hit> hit = box.intersect(ray);
        ASSERT_EQ(hit.has_value(), best_face >= 0) << "ray " << i;
        if (!hit) continue;
        ++hits;
        EXPECT_EQ(hit->primitive_id, std::uint32_t(best_face)) << "ray " << i;
        // One subtraction and one division: 2 u relative to the operands.
        const double allowed = 4 * kUnitRoundoff *
                               (std::abs(double(best)) +
                                (ray.origin.norm() + box.upper().norm() + box.lower().norm()) /
                                    ray.direction.cwiseAbs().minCoeff());
        EXPECT_NEAR(hit->t, double(best), allowed) << "ray " << i;
        EXPECT_TRUE(box.contains(hit->point));
    }
    EXPECT_GT(compared, 49000);
    EXPECT_GT(hits, 20000);
}

TEST(Box, PropertiesOnRandomRays) {
    const Box box(Point3(0.3, -1.2, 2.0), Point3(1.9, 0.4, 2.7));
    const Point3 center = 0.5 * (box.lower() + box.upper());
    const Vector3 half = 0.5 * (box.upper() - box.lower());
    // Zero on the surface: the largest of |p_i - c_i| - h_i (the box's L-infinity distance).
    const auto axis_of = [&](const Point3& p) {
        int best = 0;
        for (int axis = 1; axis < 3; ++axis) {
            if (std::abs(p[axis] - center[axis]) - half[axis] >
                std::abs(p[best] - center[best]) - half[best])
                best = axis;
        }
        return best;
    };
    const test::SurfaceDescription surface{[&](const Point3& p) {
                                               const int axis = axis_of(p);
                                               return std::abs(p[axis] - center[axis]) - half[axis];
                                           },
                                           [&](const Point3& p) {
                                               const int axis = axis_of(p);
                                               Vector3 gradient = Vector3::Zero();
                                               gradient[axis] =
                                                   p[axis] >= center[axis] ? 1.0 : -1.0;
                                               return gradient;
                                           },
                                           half.maxCoeff(), box.bounds()};
    const test::PropertyCounts counts = test::check_shape_properties(box, surface, 100000, 72);
    EXPECT_EQ(counts.rays, 100000);
    EXPECT_GT(counts.hits, 30000);
    EXPECT_GT(counts.span_checks, 100000);
}

}  // namespace
}  // namespace csgrt
