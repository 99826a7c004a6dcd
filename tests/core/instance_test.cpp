#include "csgrt/core/instance.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "csgrt/core/error.h"
#include "csgrt/core/sphere.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

using LongVector = Eigen::Matrix<long double, 3, 1>;

// The independent answer: a unit sphere under world_from_object = (L, c) is the ellipsoid
// |L^-1 (p - c)| = 1. Substituting the ray gives a quadratic in t, solved here in long double
// from the matrix directly, without the Instance or the Sphere code.
std::optional<long double> ellipsoid_nearest(const Eigen::Matrix3d& linear, const Vector3& center,
                                             const Ray& ray) {
    const Eigen::Matrix<long double, 3, 3> inverse = linear.cast<long double>().inverse();
    const LongVector o = inverse * (ray.origin.cast<long double>() - center.cast<long double>());
    const LongVector d = inverse * ray.direction.cast<long double>();
    const long double a = d.squaredNorm(), b = o.dot(d), c = o.squaredNorm() - 1.0L;
    const long double discriminant = b * b - a * c;
    if (discriminant < 0) return std::nullopt;
    const long double root = std::sqrt(discriminant);
    for (long double t : {(-b - root) / a, (-b + root) / a}) {
        if (t >= ray.t_min && t <= ray.t_max) return t;
    }
    return std::nullopt;
}

TEST(Instance, ScaledShearedSphereMatchesTheEllipsoidSolvedDirectly) {
    test::Random random(21);
    auto unit_sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    int compared = 0;
    for (int shape = 0; shape < 100; ++shape) {
        const Transform world_from_object =
            Transform::translate(random.unit_vector() * 5) *
            Transform::rotate(random.unit_vector(), random.uniform(0, kTwoPi)) *
            Transform::shear(random.integer(0, 1), 2, random.uniform(-1, 1)) *
            Transform::scale(
                Vector3(random.uniform(0.2, 3), random.uniform(0.2, 3), random.uniform(0.2, 3)));
        const Instance ellipsoid(unit_sphere, world_from_object);
        for (int i = 0; i < 1000; ++i) {
            const Ray ray =
                random.ray_between(test::enlarged(ellipsoid.bounds(), 1.0), ellipsoid.bounds());
            const std::optional<Hit> hit = ellipsoid.intersect(ray);
            const std::optional<long double> expected =
                ellipsoid_nearest(world_from_object.linear(), world_from_object.translation(), ray);
            ASSERT_EQ(hit.has_value(), expected.has_value()) << "shape " << shape << " ray " << i;
            if (!hit) continue;
            ++compared;
            // The same t in world and object space: the roots agree to the rounding of the
            // transform and the quadratic, a few hundred ulps of t for these conditionings.
            EXPECT_NEAR(hit->t, static_cast<double>(*expected), 1e-12 * (1 + std::abs(hit->t)));
            EXPECT_NEAR((hit->point - ray.at(hit->t)).norm(), 0.0, 1e-12 * (1 + ray.origin.norm()));
            // The world normal is the gradient of |L^-1 (p - c)|^2, i.e. L^-T L^-1 (p - c).
            const Eigen::Matrix3d inverse = world_from_object.inverse_linear();
            const Vector3 gradient =
                inverse.transpose() * inverse * (hit->point - world_from_object.translation());
            EXPECT_LT(hit->geometric_normal.cross(gradient.normalized()).norm(), 1e-9);
        }
    }
    EXPECT_GT(compared, 20000);
}

TEST(Instance, NestedInstancesComposeAndFinishThroughThePath) {
    auto sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    auto inner = std::make_shared<Instance>(sphere, Transform::scale(Vector3(2, 1, 1)));
    const Instance outer(inner, Transform::translate(Vector3(0, 0, 10)));
    const std::optional<Hit> hit = outer.intersect(Ray{Point3(-10, 0, 10), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 8.0, 1e-14);
    EXPECT_TRUE(hit->point.isApprox(Point3(-2, 0, 10)));
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(-1, 0, 0)));
    EXPECT_EQ(hit->shape, sphere.get());
    EXPECT_TRUE(outer.contains(Point3(1.5, 0, 10)));
    EXPECT_FALSE(outer.contains(Point3(1.5, 0, 0)));
    const SpanList spans = outer.spans(Ray{Point3(-10, 0, 10), Vector3(1, 0, 0)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_NEAR(spans[0].enter.t, 8.0, 1e-14);
    EXPECT_NEAR(spans[0].exit.t, 12.0, 1e-14);
}

TEST(Instance, PropertiesOnRandomRays) {
    auto sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    const Transform world_from_object = Transform::translate(Vector3(1, 2, 3)) *
                                        Transform::rotate(Vector3(1, 1, 0), 0.7) *
                                        Transform::scale(Vector3(0.5, 2, 1.5));
    const Instance ellipsoid(sphere, world_from_object);
    const Transform object_from_world = world_from_object.inverse();
    const Eigen::Matrix3d gradient_map =
        object_from_world.linear().transpose() * object_from_world.linear();
    const test::SurfaceDescription surface{
        [&](const Point3& p) { return object_from_world.apply_point(p).squaredNorm() - 1.0; },
        [&](const Point3& p) {
            return Vector3(2.0 * gradient_map * (p - world_from_object.translation()));
        },
        1.0, ellipsoid.bounds()};
    const test::PropertyCounts counts =
        test::check_shape_properties(ellipsoid, surface, 100000, 22);
    EXPECT_GT(counts.hits, 25000);
}

TEST(Instance, RejectsNullShape) {
    EXPECT_THROW(Instance(nullptr, Transform()), InvalidParameter);
}

}  // namespace
}  // namespace csgrt
