#include "csgrt/core/part_sphere.h"

#include <gtest/gtest.h>

// shape_properties.h uses cross() but does not include the Eigen module that defines it.
#include <Eigen/Geometry>

#include "csgrt/core/error.h"
#include "support/error_of.h"
#include "support/leaf_checks.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using LongVector = Eigen::Matrix<long double, 3, 1>;

using test::error_of;

const Point3 kOrigin(0, 0, 0);
// The half x >= 0 (phi in [0, pi]) of the unit sphere.
const PartSphere kEastHalf(kOrigin, 1.0, 0.0, kPi, 0.0, kPi);
// The lower hemisphere (theta in [pi/2, pi]): a bowl open at the top.
const PartSphere kBowl(kOrigin, 1.0, 0.0, kTwoPi, kPi / 2, kPi);

// The independent check of a hit's angles: phi and theta of the point in long double, inside
// the limits up to the angle a position error of `slack` can make at that point (slack / rho
// for phi, rho being the distance from the axis; slack / r for theta).
void expect_within_limits(const PartSphere& part, const Point3& point, double slack) {
    const LongVector q = (point.cast<long double>() - part.center().cast<long double>());
    const long double rho = std::hypot(q.x(), q.z());
    const long double r = q.norm();
    const long double theta = std::acos(std::clamp(q.y() / r, -1.0L, 1.0L));
    const long double theta_slack = slack / r + 1e-15L;
    EXPECT_GE(theta, part.theta_min() - theta_slack) << point.transpose();
    EXPECT_LE(theta, part.theta_max() + theta_slack) << point.transpose();
    if (part.azimuth().is_full() || rho <= slack) return;  // at the axis every phi is close
    long double phi = std::atan2(q.x(), q.z());
    if (phi < 0) phi += 2 * std::acos(-1.0L);
    // Offset from phi_min, reduced into [-pi, 3 pi) so both ends can be approached.
    const long double two_pi = 2 * std::acos(-1.0L);
    long double offset = std::fmod(phi - part.azimuth().min() + 2 * two_pi, two_pi);
    const long double extent = part.azimuth().max() - part.azimuth().min();
    const long double phi_slack = slack / rho + 1e-15L;
    if (offset > extent + phi_slack && offset > two_pi - phi_slack) offset -= two_pi;
    EXPECT_GE(offset, -phi_slack) << point.transpose();
    EXPECT_LE(offset, extent + phi_slack) << point.transpose();
}

TEST(PartSphere, AnalyticHitOnTheKeptHalf) {
    const std::optional<Hit> hit = kEastHalf.intersect(Ray{Point3(5, 0, 0), Vector3(-2, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 2.0);
    EXPECT_EQ(hit->point, Point3(1, 0, 0));
    EXPECT_EQ(hit->geometric_normal, Normal3(1, 0, 0));
    EXPECT_TRUE(hit->front_face);
    // phi = pi / 2 is the middle of [0, pi]; theta = pi / 2 the middle of [0, pi].
    EXPECT_NEAR(hit->uv.x(), 0.5, 4 * kUnitRoundoff);
    EXPECT_NEAR(hit->uv.y(), 0.5, 4 * kUnitRoundoff);
    EXPECT_EQ(hit->shape, &kEastHalf);
}

TEST(PartSphere, ThroughTheRemovedPartToTheFarSide) {
    // From -x: the near root (-1, 0, 0) has phi = 3 pi / 2, removed; the far side is kept and
    // is seen from inside.
    const std::optional<Hit> far = kEastHalf.intersect(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(far);
    EXPECT_EQ(far->t, 6.0);
    EXPECT_EQ(far->geometric_normal, Normal3(1, 0, 0));  // outward, not turned to the ray
    EXPECT_FALSE(far->front_face);
    // Into the bowl's opening from above: the top (theta = 0) is removed, the bottom is kept.
    const std::optional<Hit> bottom = kBowl.intersect(Ray{Point3(0, 5, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(bottom);
    EXPECT_EQ(bottom->t, 6.0);
    EXPECT_FALSE(bottom->front_face);
    // Obliquely into the opening: enters at y > 0, leaves through the bowl at y < 0.
    const Ray oblique{Point3(-2, 2.5, 0), Vector3(1, -1, 0)};
    const std::optional<Hit> inner = kBowl.intersect(oblique);
    ASSERT_TRUE(inner);
    EXPECT_LT(inner->point.y(), 0.0);
    EXPECT_GT(inner->t, 2.5);  // past the removed near root
    // Both roots removed: a cap of theta <= pi / 4 crossed at the equator.
    const PartSphere cap(kOrigin, 1.0, 0.0, kTwoPi, 0.0, kPi / 4);
    EXPECT_FALSE(cap.intersect(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)}));
    EXPECT_FALSE(cap.occluded(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)}));
}

TEST(PartSphere, AzimuthSeamAtPhiZero) {
    // Aimed exactly at x = 0, z > 0: phi = 0 = 2 pi. The seam is no boundary: the point is in
    // [0, pi / 2], in [3 pi / 2, 2 pi] and in the wrapped [3 pi / 2, 5 pi / 2].
    const Ray at_seam{Point3(0, 0.3, 5), Vector3(0, 0, -1)};
    for (const auto& [phi_min, phi_max] :
         {std::pair{0.0, kPi / 2}, std::pair{1.5 * kPi, kTwoPi}, std::pair{1.5 * kPi, 2.5 * kPi}}) {
        const PartSphere part(kOrigin, 1.0, phi_min, phi_max, 0.0, kPi);
        const std::optional<Hit> hit = part.intersect(at_seam);
        ASSERT_TRUE(hit) << phi_min << " " << phi_max;
        EXPECT_NEAR(hit->t, 5.0 - std::sqrt(1.0 - 0.09), 8 * kUnitRoundoff * 5);
        EXPECT_EQ(hit->point.x(), 0.0);
    }
    // Not in [0.1, 1]: the ray goes on to the far point (x = 0, z < 0, phi = pi), outside too.
    EXPECT_FALSE(PartSphere(kOrigin, 1.0, 0.1, 1.0, 0.0, kPi).intersect(at_seam));
    // The wrapped range [3 pi / 2, 5 pi / 2] is the half z >= 0.
    const PartSphere front(kOrigin, 1.0, 1.5 * kPi, 2.5 * kPi, 0.0, kPi);
    const Point3 toward_quarter(std::sin(0.25 * kPi), 0, std::cos(0.25 * kPi));
    EXPECT_TRUE(front.intersect(Ray{5 * toward_quarter, -toward_quarter}));  // phi = pi / 4
    const Point3 toward_back(0, 0, -1);
    const std::optional<Hit> back = front.intersect(Ray{5 * toward_back, -toward_back});
    ASSERT_TRUE(back);  // phi = pi is removed: the far side, phi = 0, is hit
    EXPECT_EQ(back->t, 6.0);
    EXPECT_NEAR(back->uv.x(), 0.5, 4 * kUnitRoundoff);  // phi = 0 is the middle of the range
}

TEST(PartSphere, HalvesMeetingAtTheSeamLeaveNoCrack) {
    // [0, pi] and [pi, 2 pi] share the seams phi = 0 and phi = pi; rays aimed at them from
    // oblique directions land with x = +-tiny, and one half or the other must take each.
    const PartSphere east(kOrigin, 1.0, 0.0, kPi, 0.0, kPi);
    const PartSphere west(kOrigin, 1.0, kPi, kTwoPi, 0.0, kPi);
    test::Random random(81);
    int rays = 0;
    for (int i = 0; i < 40000; ++i) {
        const double y = random.uniform(-0.95, 0.95);
        const double z = (i % 2 ? 1.0 : -1.0) * std::sqrt(1 - y * y);
        const Point3 target(0, y, z);
        Vector3 away = random.unit_vector();
        if (away.dot(target) < 0.2) continue;  // start outside, in front of the target
        const Point3 origin = target + random.uniform(1, 4) * away;
        const Ray ray{origin, target - origin};
        ++rays;
        const std::optional<Hit> a = east.intersect(ray), b = west.intersect(ray);
        ASSERT_TRUE(a || b) << "crack at ray " << i;
        // The near point of the full sphere is taken by one half (the other may see its far
        // side instead).
        const double t = std::min(a ? a->t : kInfinity, b ? b->t : kInfinity);
        EXPECT_NEAR(t, 1.0, 1e-12) << "ray " << i;
    }
    EXPECT_GT(rays, 10000);
}

TEST(PartSphere, PolesBelongToEveryAzimuth) {
    const PartSphere wedge(kOrigin, 1.0, 0.5, 1.0, 0.0, kPi);
    const std::optional<Hit> north = wedge.intersect(Ray{Point3(0, 5, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(north);
    EXPECT_EQ(north->t, 4.0);
    EXPECT_EQ(north->geometric_normal, Normal3(0, 1, 0));
    // Removing the pole by theta_min makes the same ray miss both poles' neighbourhoods.
    const PartSphere band(kOrigin, 1.0, 0.5, 1.0, 0.1, kPi - 0.1);
    EXPECT_FALSE(band.intersect(Ray{Point3(0, 5, 0), Vector3(0, -1, 0)}));
}

TEST(PartSphere, HemisphereRimBelongsToBothHalves) {
    // The equator y = 0 is the limit theta = pi / 2 of the dome and of the bowl; the double
    // nearest pi / 2 has a cosine of 6e-17, which the limit treats as the equator exactly.
    const PartSphere dome(kOrigin, 1.0, 0.0, kTwoPi, 0.0, kPi / 2);
    const Ray along_equator{Point3(0, 0, -5), Vector3(0, 0, 1)};
    ASSERT_TRUE(dome.intersect(along_equator));
    EXPECT_EQ(dome.intersect(along_equator)->t, 4.0);
    ASSERT_TRUE(kBowl.intersect(along_equator));
    EXPECT_EQ(kBowl.intersect(along_equator)->t, 4.0);
    // Just above the equator only the dome is hit.
    const Ray above{Point3(0, 1e-9, -5), Vector3(0, 0, 1)};
    EXPECT_TRUE(dome.intersect(above));
    ASSERT_TRUE(kBowl.intersect(above).has_value() == false);
}

TEST(PartSphere, TangentRays) {
    // Tangent at (1, 0, 0), which is kept: a double root, determined to about sqrt(u).
    const std::optional<Hit> kept = kEastHalf.intersect(Ray{Point3(1, -5, 0), Vector3(0, 1, 0)});
    ASSERT_TRUE(kept);
    EXPECT_NEAR(kept->t, 5.0, 1e-7);
    // Tangent at (-1, 0, 0), which is removed.
    EXPECT_FALSE(kEastHalf.intersect(Ray{Point3(-1, -5, 0), Vector3(0, 1, 0)}));
    // Parallel to the axis, missing the sphere.
    EXPECT_FALSE(kEastHalf.intersect(Ray{Point3(1.5, -5, 0), Vector3(0, 1, 0)}));
}

TEST(PartSphere, IntervalHonouredAtBothEnds) {
    const Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};  // roots 4 (removed) and 6 (kept)
    Ray clipped = ray;
    clipped.t_max = next_down(6.0);
    EXPECT_FALSE(kEastHalf.intersect(clipped));
    EXPECT_FALSE(kEastHalf.occluded(clipped));
    clipped.t_max = 6.0;
    ASSERT_TRUE(kEastHalf.intersect(clipped));
    EXPECT_EQ(kEastHalf.intersect(clipped)->t, 6.0);
    EXPECT_TRUE(kEastHalf.occluded(clipped));
    const Ray reverse{Point3(5, 0, 0), Vector3(-1, 0, 0)};  // roots 4 (kept) and 6 (removed)
    clipped = reverse;
    clipped.t_min = 4.0;
    EXPECT_TRUE(kEastHalf.intersect(clipped));
    clipped.t_min = next_up(4.0);
    EXPECT_FALSE(kEastHalf.intersect(clipped));
    EXPECT_FALSE(kEastHalf.occluded(clipped));
}

TEST(PartSphere, InvalidRaysNeverHit) {
    test::expect_invalid_rays_miss(kEastHalf, Ray{Point3(5, 0, 0), Vector3(-1, 0, 0)});
}

TEST(PartSphere, RejectsBadParametersNamingThem) {
    const auto error = [](double radius, double phi_min, double phi_max, double theta_min,
                          double theta_max) {
        return error_of(
            [&] { PartSphere(kOrigin, radius, phi_min, phi_max, theta_min, theta_max); });
    };
    const auto names = [](const std::string& message, const char* parameter) {
        return message.find(std::string("PartSphere: ") + parameter) != std::string::npos;
    };
    const double nan = std::nan("");
    EXPECT_TRUE(names(error(0.0, 0, 1, 0, 1), "radius"));
    EXPECT_TRUE(names(error(nan, 0, 1, 0, 1), "radius"));
    EXPECT_TRUE(names(error(1, -0.1, 1, 0, 1), "phi_min"));
    EXPECT_TRUE(names(error(1, 7.0, 8, 0, 1), "phi_min"));
    EXPECT_TRUE(names(error(1, nan, 1, 0, 1), "phi_min"));
    EXPECT_TRUE(names(error(1, 1, 1, 0, 1), "phi_max"));
    EXPECT_TRUE(names(error(1, 1, 0.5, 0, 1), "phi_max"));
    EXPECT_TRUE(names(error(1, 1, 1 + kTwoPi + 1e-9, 0, 1), "phi_max"));
    EXPECT_TRUE(names(error(1, 0, nan, 0, 1), "phi_max"));
    EXPECT_TRUE(names(error(1, 0, 1, -0.1, 1), "theta_min"));
    EXPECT_TRUE(names(error(1, 0, 1, kPi, kPi), "theta_min"));
    EXPECT_TRUE(names(error(1, 0, 1, nan, 1), "theta_min"));
    EXPECT_TRUE(names(error(1, 0, 1, 1, 1), "theta_max"));
    EXPECT_TRUE(names(error(1, 0, 1, 0, 3.2), "theta_max"));
    EXPECT_TRUE(names(error(1, 0, 1, 0, nan), "theta_max"));
    EXPECT_TRUE(names(error_of([&] { PartSphere(Point3(nan, 0, 0), 1, 0, 1, 0, 1); }), "center"));
    // The extremes are valid: the whole sphere, and a range wrapping all the way round.
    EXPECT_NO_THROW(PartSphere(kOrigin, 1, 0, kTwoPi, 0, kPi));
    EXPECT_NO_THROW(PartSphere(kOrigin, 1, next_down(kTwoPi), 2 * kTwoPi, 0, kPi));
    EXPECT_TRUE(names(error(1, kTwoPi, 2 * kTwoPi, 0, 1), "phi_min"));  // that is phi_min 0
    EXPECT_TRUE(PartSphere(kOrigin, 1, 1.0, 1.0 + kTwoPi, 0, kPi).azimuth().is_full());
}

TEST(PartSphere, MatchesALongDoubleSolveWithLimits) {
    test::Random random(82);
    const long double two_pi = 2 * std::acos(-1.0L);
    int compared = 0, hits = 0, far_side = 0;
    for (int i = 0; i < 50000; ++i) {
        const double phi_min = random.uniform(0, kTwoPi);
        const double phi_max = phi_min + random.uniform(0.2, kTwoPi);
        const double theta_min = random.uniform(0, 1.5);
        const double theta_max = random.uniform(theta_min + 0.2, kPi);
        const PartSphere part(random.in_box(Aabb(Point3(-3, -3, -3), Point3(3, 3, 3))),
                              random.uniform(0.5, 2), phi_min, phi_max, theta_min, theta_max);
        Ray ray = random.ray_between(test::enlarged(part.bounds(), 1.0), part.bounds());
        if (i % 5 == 0) ray.origin = random.in_box(part.bounds());
        const LongVector f = (ray.origin - part.center()).cast<long double>();
        const LongVector d = ray.direction.cast<long double>();
        const long double a = d.squaredNorm(), b = f.dot(d),
                          c = f.squaredNorm() - square(part.radius());
        const long double discriminant = b * b - a * c;
        long double expected = -1;
        bool ambiguous = std::abs(discriminant) < 1e-9L * b * b;
        if (discriminant >= 0) {
            const long double root = std::sqrt(discriminant);
            int index = 0;
            for (const long double t : {(-b - root) / a, (-b + root) / a}) {
                ++index;
                if (std::abs(t) * std::sqrt(a) < 1e-9L) ambiguous = true;
                if (t < 0) continue;
                const LongVector q = f + t * d;
                const long double theta = std::acos(std::clamp(q.y() / part.radius(), -1.0L, 1.0L));
                long double offset =
                    std::fmod(std::atan2(q.x(), q.z()) - phi_min + 2 * two_pi, two_pi);
                const long double extent = phi_max - phi_min;
                // Decided beyond double rounding only 1e-9 away from every limit.
                for (const long double gap : {theta - theta_min, theta_max - theta, offset,
                                              extent - offset, two_pi - offset}) {
                    if (std::abs(gap) < 1e-9L) ambiguous = true;
                }
                const bool inside = theta >= theta_min && theta <= theta_max && offset <= extent;
                if (inside && expected < 0) {
                    expected = t;
                    if (index == 2) ++far_side;
                }
            }
        }
        if (ambiguous) continue;
        ++compared;
        const std::optional<Hit> hit = part.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected >= 0) << "ray " << i;
        if (!hit) continue;
        ++hits;
        // The sphere's roots are accurate to a few ulps of the distances involved.
        EXPECT_NEAR(hit->t, double(expected),
                    64 * kUnitRoundoff * (std::abs(hit->t) + (f.norm() + 2) / std::sqrt(a)))
            << "ray " << i;
    }
    EXPECT_GT(compared, 45000);
    EXPECT_GT(hits, 10000);
    EXPECT_GT(far_side, 1000);  // hits that went through the removed part
}

TEST(PartSphere, PropertiesOnRandomRays) {
    for (const auto& [phi_min, phi_max, theta_min, theta_max] :
         {std::tuple{0.3, 4.0, 0.4, 2.5}, std::tuple{5.0, 8.0, 0.0, 1.2},
          std::tuple{0.0, kTwoPi, kPi / 2, kPi}}) {
        const PartSphere part(Point3(0.3, -1.2, 2.0), 1.7, phi_min, phi_max, theta_min, theta_max);
        const test::SurfaceDescription surface =
            test::sphere_surface(part.center(), part.radius(), part.bounds());
        const test::PropertyCounts counts = test::check_shape_properties(part, surface, 100000, 83);
        EXPECT_EQ(counts.rays, 100000);
        EXPECT_GT(counts.hits, 20000);
        // The same rays again: every hit lies within the limits (the property check knows only
        // the full sphere), and inside the bounds.
        test::Random random(83);
        const Aabb from = test::enlarged(surface.region, 1.0);
        const Aabb toward = test::enlarged(surface.region, 0.05);
        for (int i = 0; i < 100000; ++i) {
            Ray ray = random.ray_between(from, toward);
            if (i % 5 == 0) ray.origin = random.in_box(surface.region);
            const std::optional<Hit> hit = part.intersect(ray);
            if (!hit) continue;
            // The finished point is o + t d projected onto the sphere: off by a few ulps of
            // the magnitudes, as the property check allows.
            const double slack =
                64 * kUnitRoundoff *
                (ray.origin.norm() + std::abs(hit->t) * ray.direction.norm() + part.radius());
            expect_within_limits(part, hit->point, slack);
            EXPECT_TRUE(part.bounds().contains(hit->point)) << "ray " << i;
            EXPECT_GE(hit->uv.minCoeff(), 0.0);
            EXPECT_LE(hit->uv.maxCoeff(), 1.0);
            if (HasFailure()) return;
        }
    }
}

}  // namespace
}  // namespace csgrt
