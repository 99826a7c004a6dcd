#include "csgrt/core/annulus.h"

#include <gtest/gtest.h>

#include "csgrt/core/error.h"
#include "support/error_of.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using LongVector = Eigen::Matrix<long double, 3, 1>;

using test::error_of;

const Normal3 kUp(0, 1, 0);
// r in [1, 2] at height 1, all the way round.
const Annulus kRing(Point3(0, 1, 0), kUp, 1.0, 2.0);
// The quarter disk x >= 0, z >= 0 (phi in [0, pi / 2]) of radius 2 at the origin.
const Annulus kQuarter(Point3(0, 0, 0), kUp, 0.0, 2.0, 0.0, kPi / 2);

Ray down_at(double x, double z, double height = 5) {
    return Ray{Point3(x, height, z), Vector3(0, -1, 0)};
}

TEST(Annulus, AnalyticHitWithUv) {
    const std::optional<Hit> hit = kRing.intersect(down_at(1.5, 0));
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->point, Point3(1.5, 1, 0));
    EXPECT_EQ(hit->geometric_normal, kUp);
    EXPECT_TRUE(hit->front_face);
    // Halfway between the radii; phi = atan2(1.5, 0) = pi / 2 is a quarter of the full range.
    EXPECT_NEAR(hit->uv.x(), 0.5, 4 * kUnitRoundoff);
    EXPECT_NEAR(hit->uv.y(), 0.25, 4 * kUnitRoundoff);
    EXPECT_EQ(hit->shape, &kRing);
}

TEST(Annulus, HoleAndBothRims) {
    EXPECT_FALSE(kRing.intersect(down_at(0.5, 0)));  // through the hole: nothing beyond
    EXPECT_FALSE(kRing.occluded(down_at(0.5, 0)));
    EXPECT_FALSE(kRing.intersect(down_at(0, 0)));
    EXPECT_TRUE(kRing.intersect(down_at(1, 0)));   // inner rim, r = 1 exactly
    EXPECT_TRUE(kRing.intersect(down_at(0, -2)));  // outer rim, r = 2 exactly
    EXPECT_FALSE(kRing.intersect(down_at(next_down(1.0), 0)));
    EXPECT_FALSE(kRing.intersect(down_at(0, -next_up(2.0))));
    EXPECT_FALSE(kRing.intersect(down_at(1.5, 1.5)));  // r = 2.12
}

TEST(Annulus, PartDiskKeepsItsSectorAndItsCenter) {
    EXPECT_TRUE(kQuarter.intersect(down_at(0.5, 0.5)));
    EXPECT_FALSE(kQuarter.intersect(down_at(-0.5, 0.5)));
    EXPECT_FALSE(kQuarter.intersect(down_at(0.5, -0.5)));
    EXPECT_TRUE(kQuarter.intersect(down_at(0, 0)));  // the center belongs to every azimuth
    // Both radial edges: phi = 0 (x = 0, z > 0) and phi = pi / 2 (z = 0, x > 0).
    EXPECT_TRUE(kQuarter.intersect(down_at(0, 1)));
    EXPECT_TRUE(kQuarter.intersect(down_at(1, 0)));
    const std::optional<Hit> edge = kQuarter.intersect(down_at(1, 0));
    ASSERT_TRUE(edge);
    EXPECT_NEAR(edge->uv.y(), 1.0, 4 * kUnitRoundoff);  // phi_max
}

TEST(Annulus, SeamAndWrappedRanges) {
    // phi = 0 (x = 0, z > 0) is in [3 pi / 2, 2 pi] as well as in [0, pi / 2].
    const Annulus last_quarter(Point3(0, 0, 0), kUp, 0.5, 2.0, 1.5 * kPi, kTwoPi);
    EXPECT_TRUE(last_quarter.intersect(down_at(0, 1)));
    EXPECT_TRUE(last_quarter.intersect(down_at(-1, 0.1)));
    EXPECT_FALSE(last_quarter.intersect(down_at(1, 0.1)));
    // [3 pi / 2, 5 pi / 2] wraps through phi = 0: the half z >= 0.
    const Annulus front(Point3(0, 0, 0), kUp, 0.5, 2.0, 1.5 * kPi, 2.5 * kPi);
    EXPECT_TRUE(front.intersect(down_at(1, 0.1)));
    EXPECT_TRUE(front.intersect(down_at(-1, 0.1)));
    EXPECT_FALSE(front.intersect(down_at(0.3, -1)));
    const std::optional<Hit> middle = front.intersect(down_at(0, 1));
    ASSERT_TRUE(middle);
    EXPECT_NEAR(middle->uv.y(), 0.5, 4 * kUnitRoundoff);  // phi = 0 is the middle of the range
}

TEST(Annulus, TiltedNormalUsesItsFrame) {
    // Normal +z: the frame's z_axis is R z for the rotation taking +y to +z, i.e. -y, and its
    // x_axis is +x; so phi = atan2(p . x, -p . y).
    const Annulus facing_z(Point3(0, 0, 3), Normal3(0, 0, 1), 0.0, 2.0, 0.0, kPi / 2);
    EXPECT_EQ(facing_z.frame().z_axis, Vector3(0, -1, 0));
    EXPECT_EQ(facing_z.frame().x_axis, Vector3(1, 0, 0));
    // (1, -1): x > 0 and -y > 0, inside the quarter; (1, 1) is not.
    EXPECT_TRUE(facing_z.intersect(Ray{Point3(1, -1, 0), Vector3(0, 0, 1)}));
    EXPECT_FALSE(facing_z.intersect(Ray{Point3(1, 1, 0), Vector3(0, 0, 1)}));
}

TEST(Annulus, ParallelRaysNeverHitEvenInThePlane) {
    test::expect_misses(kRing, {Ray{Point3(-5, 1, 1.5), Vector3(1, 0, 0)},
                                Ray{Point3(-5, 1.2, 1.5), Vector3(1, 0, 0.1)}});
}

TEST(Annulus, RayStartingOnIt) {
    Ray ray{Point3(1.5, 1, 0), Vector3(0.2, -1, 0)};
    const std::optional<Hit> hit = kRing.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 0.0);
    EXPECT_TRUE(hit->front_face);  // moving against the normal, as a ray from above would
    ray.t_min = 1e-12;
    EXPECT_FALSE(kRing.intersect(ray));
}

TEST(Annulus, IntervalHonouredAtBothEnds) {
    const Ray ray = down_at(1.5, 0);  // crosses at t = 4
    test::expect_interval_honoured(kRing, ray, 4.0);
}

TEST(Annulus, InvalidRaysNeverHit) {
    for (const Ray& ray : test::invalid_variants(Ray{Point3(1.5, 5, 0), Vector3(0, -1, 0)})) {
        EXPECT_FALSE(kRing.intersect(ray));
        EXPECT_FALSE(kRing.occluded(ray));
        EXPECT_FALSE(kQuarter.intersect(ray));
    }
}

TEST(Annulus, RejectsBadParametersNamingThem) {
    const Point3 o(0, 0, 0);
    const auto names = [](const std::string& message, const char* parameter) {
        return message.find(std::string("Annulus: ") + parameter) != std::string::npos;
    };
    const double nan = std::nan("");
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, -0.1, 1); }), "inner_radius"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, 1, 1); }), "inner_radius"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, 2, 1); }), "inner_radius"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, nan, 1); }), "inner_radius"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, 0, 0); }), "outer_radius"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, 0, kInfinity); }), "outer_radius"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, Normal3(0, 0, 0), 0, 1); }), "normal"));
    EXPECT_TRUE(names(error_of([&] { Annulus(Point3(nan, 0, 0), kUp, 0, 1); }), "center"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, 0, 1, -1, 1); }), "phi_min"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, 0, 1, 1, 1); }), "phi_max"));
    EXPECT_TRUE(names(error_of([&] { Annulus(o, kUp, 0, 1, 0, 7); }), "phi_max"));
}

TEST(Annulus, MatchesALongDoubleSolve) {
    test::Random random(91);
    const long double two_pi = 2 * std::acos(-1.0L);
    int compared = 0, hits = 0;
    for (int i = 0; i < 50000; ++i) {
        const double outer = random.uniform(0.5, 3);
        const double phi_min = random.uniform(0, kTwoPi);
        const Annulus annulus(random.in_box(Aabb(Point3(-5, -5, -5), Point3(5, 5, 5))),
                              random.unit_vector(), random.uniform(0, 0.8) * outer, outer, phi_min,
                              phi_min + random.uniform(0.2, kTwoPi));
        const Ray ray = random.ray_between(test::enlarged(annulus.bounds(), 2.0), annulus.bounds());
        const test::LongPlaneSolve solve =
            test::long_plane_solve(annulus.center(), annulus.normal(), ray);
        const long double t = solve.t;
        const LongVector q = solve.offset();
        const long double r = q.norm();
        const long double x = q.dot(annulus.frame().x_axis.cast<long double>());
        const long double z = q.dot(annulus.frame().z_axis.cast<long double>());
        const long double offset =
            std::fmod(std::atan2(x, z) - annulus.azimuth().min() + 2 * two_pi, two_pi);
        const long double extent = annulus.azimuth().max() - annulus.azimuth().min();
        // Decided beyond double rounding only 1e-9 away from every limit.
        bool ambiguous = std::abs(t) < 1e-9L;
        for (const long double gap : {r - annulus.inner_radius(), annulus.outer_radius() - r,
                                      offset, extent - offset, two_pi - offset}) {
            if (std::abs(gap) < 1e-9L) ambiguous = true;
        }
        if (ambiguous) continue;
        ++compared;
        const bool expected = t >= 0 && r >= annulus.inner_radius() &&
                              r <= annulus.outer_radius() && offset <= extent;
        const std::optional<Hit> hit = annulus.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected) << "ray " << i;
        if (!hit) continue;
        ++hits;
        // The plane solve's forward error, as for the plane.
        EXPECT_NEAR(hit->t, double(t), double(solve.bound())) << "ray " << i;
        const long double radial =
            (r - annulus.inner_radius()) / (annulus.outer_radius() - annulus.inner_radius());
        EXPECT_NEAR(hit->uv.x(), double(radial), 1e-12);
        EXPECT_NEAR(hit->uv.y(), double(offset / extent), 1e-12);
    }
    EXPECT_GT(compared, 49000);
    EXPECT_GT(hits, 5000);
}

TEST(Annulus, PropertiesOnRandomRays) {
    for (const auto& [inner, phi_min, phi_max] :
         {std::tuple{0.6, 0.0, kTwoPi}, std::tuple{0.0, 1.0, 4.0}, std::tuple{0.4, 5.0, 8.5}}) {
        const Annulus annulus(Point3(0.3, -1.2, 2.0), Normal3(0.2, 1.0, -0.4), inner, 1.7, phi_min,
                              phi_max);
        const test::SurfaceDescription surface = test::plane_surface(
            annulus.center(), annulus.normal(), annulus.outer_radius(), annulus.bounds());
        const test::PropertyCounts counts =
            test::check_shape_properties(annulus, surface, 100000, 92);
        EXPECT_EQ(counts.rays, 100000);
        EXPECT_GT(counts.hits, 15000);
        // The same rays: every hit lies within the radii and the azimuth range, up to the
        // angle a position error of `slack` makes at distance r from the center.
        test::Random random(92);
        const Aabb from = test::enlarged(surface.region, 1.0);
        const Aabb toward = test::enlarged(surface.region, 0.05);
        const long double two_pi = 2 * std::acos(-1.0L);
        for (int i = 0; i < 100000; ++i) {
            Ray ray = random.ray_between(from, toward);
            if (i % 5 == 0) ray.origin = random.in_box(surface.region);
            const std::optional<Hit> hit = annulus.intersect(ray);
            if (!hit) continue;
            const double slack = 64 * kUnitRoundoff *
                                 (ray.origin.norm() + std::abs(hit->t) * ray.direction.norm() +
                                  annulus.outer_radius());
            const LongVector q = (hit->point - annulus.center()).cast<long double>();
            const long double r = q.norm();
            EXPECT_GE(r, annulus.inner_radius() - slack) << "ray " << i;
            EXPECT_LE(r, annulus.outer_radius() + slack) << "ray " << i;
            EXPECT_TRUE(annulus.bounds().contains(hit->point)) << "ray " << i;
            if (r <= slack || annulus.azimuth().is_full()) continue;
            const long double x = q.dot(annulus.frame().x_axis.cast<long double>());
            const long double z = q.dot(annulus.frame().z_axis.cast<long double>());
            long double offset = std::fmod(std::atan2(x, z) - phi_min + 2 * two_pi, two_pi);
            const long double phi_slack = slack / r + 1e-15L;
            if (offset > two_pi - phi_slack) offset -= two_pi;
            EXPECT_GE(offset, -phi_slack) << "ray " << i;
            EXPECT_LE(offset, phi_max - phi_min + phi_slack) << "ray " << i;
            if (HasFailure()) return;
        }
    }
}

}  // namespace
}  // namespace csgrt
