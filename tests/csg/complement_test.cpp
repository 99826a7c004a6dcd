#include "csgrt/csg/complement.h"

#include <gtest/gtest.h>

#include "csgrt/core/error.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "support/random.h"

namespace csgrt {
namespace {

const auto kBall = std::make_shared<Sphere>(Point3(1, 0, 0), 2.0);

TEST(Complement, SpansAreTheGapsOfTheOperandsToInfinity) {
    const Complement outside(kBall);
    // Along x from x = -5: the ball covers [-1, 3], t in [4, 8].
    const SpanList spans = outside.spans(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)});
    ASSERT_EQ(spans.size(), 2u);
    EXPECT_EQ(spans[0].enter.t, -kInfinity);
    EXPECT_EQ(spans[0].enter.shape, nullptr);
    EXPECT_EQ(spans[0].exit.t, 4.0);
    EXPECT_EQ(spans[0].exit.shape, kBall.get());
    EXPECT_TRUE(spans[0].exit.flip_normal);
    EXPECT_EQ(spans[1].enter.t, 8.0);
    EXPECT_TRUE(spans[1].enter.flip_normal);
    EXPECT_EQ(spans[1].exit.t, kInfinity);
    EXPECT_EQ(spans[1].exit.shape, nullptr);
    // A line that misses the ball is outside it everywhere.
    const SpanList everywhere = outside.spans(Ray{Point3(-5, 3, 0), Vector3(1, 0, 0)});
    ASSERT_EQ(everywhere.size(), 1u);
    EXPECT_EQ(everywhere[0].enter.t, -kInfinity);
    EXPECT_EQ(everywhere[0].exit.t, kInfinity);
}

TEST(Complement, ItsNormalPointsIntoTheOperand) {
    const Complement outside(kBall);
    // From the ball's centre outward: the ray enters the complement at x = 3.
    const std::optional<Hit> hit = outside.intersect(Ray{Point3(1, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 2.0);
    EXPECT_EQ(hit->geometric_normal, Normal3(-1, 0, 0));
    EXPECT_TRUE(hit->front_face);  // arriving from outside the complement
    EXPECT_TRUE(outside.contains(Point3(3.1, 0, 0)));
    EXPECT_FALSE(outside.contains(Point3(2.9, 0, 0)));
}

TEST(Complement, IntersectingWithTheComplementIsSubtracting) {
    // A box minus the ball, written both ways: the same hits, and membership as the closed
    // form says (inside the box, outside the ball).
    const auto box = std::make_shared<Box>(Point3(-1, -1, -1), Point3(2, 1.5, 1));
    const auto with_not = make_intersection({box, std::make_shared<Complement>(kBall)});
    const auto minus = make_difference(box, {kBall});
    test::Random random(13);
    int hits = 0;
    for (int i = 0; i < 3000; ++i) {
        const Ray ray = random.ray_between(Aabb(Point3(-5, -5, -5), Point3(5, 5, 5)),
                                           Aabb(Point3(-1, -1, -1), Point3(2, 1.5, 1)));
        const std::optional<Hit> a = with_not->intersect(ray);
        const std::optional<Hit> b = minus->intersect(ray);
        ASSERT_EQ(a.has_value(), b.has_value()) << i;
        EXPECT_EQ(with_not->occluded(ray), b.has_value()) << i;
        if (!a) continue;
        ++hits;
        EXPECT_EQ(a->t, b->t) << i;
        EXPECT_TRUE(a->geometric_normal.isApprox(b->geometric_normal, 1e-15)) << i;
        for (const double step : {-1e-6, 1e-6}) {
            const Point3 p = ray.at(a->t + step / ray.direction.norm());
            const bool in_box = (p.array() > box->bounds().lower.array()).all() &&
                                (p.array() < box->bounds().upper.array()).all();
            EXPECT_EQ(with_not->contains(p), in_box && (p - Point3(1, 0, 0)).norm() > 2) << i;
        }
    }
    EXPECT_GT(hits, 1000);
}

TEST(Complement, TwiceIsTheOperandAndASlabIsTwoHalfSpaces) {
    const Complement twice(std::make_shared<Complement>(kBall));
    test::Random random(17);
    for (int i = 0; i < 500; ++i) {
        const Ray ray = random.ray_between(Aabb(Point3(-5, -5, -5), Point3(5, 5, 5)),
                                           kBall->bounds());
        const SpanList expected = kBall->spans(ray);
        const SpanList actual = twice.spans(ray);
        ASSERT_EQ(actual.size(), expected.size()) << i;
        for (std::size_t k = 0; k < actual.size(); ++k) {
            EXPECT_EQ(actual[k].enter.t, expected[k].enter.t) << i;
            EXPECT_EQ(actual[k].exit.t, expected[k].exit.t) << i;
            EXPECT_FALSE(actual[k].enter.flip_normal) << i;  // flipped twice
        }
    }
    // 0 < y < 1 as below y = 1 and not below y = 0: one span from y = 0 to y = 1.
    const auto slab =
        make_intersection({std::make_shared<HalfSpace>(Point3(0, 1, 0), Normal3(0, 1, 0)),
                           std::make_shared<Complement>(std::make_shared<HalfSpace>(
                               Point3(0, 0, 0), Normal3(0, 1, 0)))});
    const SpanList spans = slab->spans(Ray{Point3(0, -3, 0), Vector3(0, 2, 0)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 1.5);
    EXPECT_EQ(spans[0].exit.t, 2.0);
    const std::optional<Hit> floor = slab->intersect(Ray{Point3(0, -3, 0), Vector3(0, 2, 0)});
    ASSERT_TRUE(floor);
    EXPECT_EQ(floor->geometric_normal, Normal3(0, -1, 0));  // out of the slab, downward
}

TEST(Complement, RefusesAnOpenOperand) {
    EXPECT_THROW(Complement(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 1, 0))),
                 InvalidParameter);
    EXPECT_THROW(Complement(nullptr), InvalidParameter);
}

}  // namespace
}  // namespace csgrt
