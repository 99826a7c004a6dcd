#include "csgrt/core/transform.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "csgrt/core/error.h"
#include "support/random.h"

namespace csgrt {
namespace {

// Compositions of a few exact operations: error of a handful of double operations on values
// of order 10, i.e. well under 1e-12.
constexpr double kTolerance = 1e-12;

TEST(Transform, ElementaryMapsAnalytic) {
    EXPECT_TRUE(Transform::translate(Vector3(1, 2, 3))
                    .apply_point(Point3(1, 1, 1))
                    .isApprox(Point3(2, 3, 4)));
    EXPECT_TRUE(Transform::translate(Vector3(1, 2, 3))
                    .apply_vector(Vector3(1, 1, 1))
                    .isApprox(Vector3(1, 1, 1)));
    EXPECT_TRUE(
        Transform::scale(Vector3(2, 3, 4)).apply_point(Point3(1, 1, 1)).isApprox(Point3(2, 3, 4)));
    const Point3 rotated =
        Transform::rotate(Vector3(0, 0, 1), kPi / 2).apply_point(Point3(1, 0, 0));
    EXPECT_NEAR((rotated - Point3(0, 1, 0)).norm(), 0.0, kTolerance);
    EXPECT_TRUE(Transform::shear(0, 1, 2.0).apply_point(Point3(1, 1, 0)).isApprox(Point3(3, 1, 0)));
}

TEST(Transform, NormalsStayPerpendicularUnderShearAndNonUniformScale) {
    test::Random random(3);
    for (int i = 0; i < 1000; ++i) {
        const Transform m = Transform::shear(0, 2, random.uniform(-3, 3)) *
                            Transform::scale(Vector3(random.uniform(0.1, 5), random.uniform(0.1, 5),
                                                     random.uniform(0.1, 5))) *
                            Transform::rotate(random.unit_vector(), random.uniform(0, kTwoPi));
        const Normal3 n = random.unit_vector();
        const Vector3 tangent = n.unitOrthogonal();
        const double dot = m.apply_normal(n).normalized().dot(m.apply_vector(tangent).normalized());
        EXPECT_NEAR(dot, 0.0, kTolerance);
    }
}

TEST(Transform, CompositionAndCachedInverse) {
    test::Random random(4);
    for (int i = 0; i < 1000; ++i) {
        const Transform a = Transform::translate(random.unit_vector() * 3) *
                            Transform::rotate(random.unit_vector(), random.uniform(0, kTwoPi));
        const Transform b = Transform::scale(Vector3(0.5, 2, 3)) * Transform::shear(1, 0, 0.7);
        const Point3 p = random.unit_vector() * 2;
        EXPECT_NEAR(((a * b).apply_point(p) - a.apply_point(b.apply_point(p))).norm(), 0.0,
                    kTolerance);
        EXPECT_NEAR(((a * b).inverse().apply_point((a * b).apply_point(p)) - p).norm(), 0.0,
                    kTolerance);
        EXPECT_TRUE((a * a.inverse()).matrix().isApprox(Eigen::Matrix4d::Identity(), kTolerance));
    }
}

TEST(Transform, RayParameterIsPreserved) {
    const Transform m = Transform::translate(Vector3(1, -2, 5)) *
                        Transform::scale(Vector3(3, 0.5, 2)) * Transform::shear(2, 0, 1.5);
    const Ray ray{Point3(0.3, 0.2, -1), Vector3(0.1, 0.7, 0.4), 0.25, 7.5};
    const Ray mapped = m.apply(ray);
    EXPECT_EQ(mapped.t_min, ray.t_min);
    EXPECT_EQ(mapped.t_max, ray.t_max);
    for (double t : {0.0, 1.0, 3.7}) {
        EXPECT_NEAR((mapped.at(t) - m.apply_point(ray.at(t))).norm(), 0.0, kTolerance);
    }
}

TEST(Transform, BoxBoundsEveryMappedCorner) {
    test::Random random(5);
    const Aabb box(Point3(-1, 2, 0), Point3(3, 4, 0.5));
    for (int i = 0; i < 1000; ++i) {
        const Transform m = Transform::rotate(random.unit_vector(), random.uniform(0, kTwoPi)) *
                            Transform::shear(0, 1, random.uniform(-2, 2)) *
                            Transform::translate(random.unit_vector() * 1e3);
        const Aabb mapped = m.apply(box);
        for (int corner = 0; corner < 8; ++corner) {
            const Point3 p((corner & 1) ? box.upper.x() : box.lower.x(),
                           (corner & 2) ? box.upper.y() : box.lower.y(),
                           (corner & 4) ? box.upper.z() : box.lower.z());
            EXPECT_TRUE(mapped.contains(m.apply_point(p)))
                << "transform " << i << " corner " << corner;
        }
    }
    EXPECT_TRUE(Transform::rotate(Vector3(1, 0, 0), 1.0).apply(Aabb::empty()).is_empty());
}

TEST(Transform, RejectsSingularAndNonFinite) {
    EXPECT_THROW(Transform::scale(Vector3(1, 0, 1)), InvalidParameter);
    EXPECT_THROW(Transform::scale(Vector3(1, std::nan(""), 1)), InvalidParameter);
    EXPECT_THROW(Transform::translate(Vector3(kInfinity, 0, 0)), InvalidParameter);
    EXPECT_THROW(Transform::rotate(Vector3(0, 0, 0), 1.0), InvalidParameter);
    EXPECT_THROW(Transform::shear(1, 1, 2.0), InvalidParameter);
    Eigen::Matrix3d flat = Eigen::Matrix3d::Identity();
    flat.col(2) = flat.col(0) + 1e-14 * flat.col(1);  // two columns almost parallel
    EXPECT_THROW(Transform(flat, Vector3::Zero()), InvalidParameter);
    Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
    projective(3, 0) = 1;
    EXPECT_THROW(Transform::from_matrix(projective), InvalidParameter);
    // Extreme but invertible scales are fine: the test is scale-free.
    EXPECT_NO_THROW(Transform::scale(Vector3(1e-9, 1e9, 1)));
    try {
        Transform::scale(Vector3(1, 0, 1));
    } catch (const InvalidParameter& error) {
        EXPECT_NE(std::string(error.what()).find("factors"), std::string::npos) << error.what();
    }
}

}  // namespace
}  // namespace csgrt
