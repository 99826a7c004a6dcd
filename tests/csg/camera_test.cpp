#include "csgrt/csg/camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "csgrt/core/error.h"

namespace csgrt {
namespace {

TEST(Camera, PinholeCentreRayHitsLookAtAndCornersSpanTheFieldOfView) {
    Camera camera;
    camera.position = Point3(1, 2, 3);
    camera.look_at = Point3(1, 2, -7);
    camera.vertical_fov_degrees = 90.0;
    const Ray centre = camera.generate_ray(0.5, 0.5, 2.0);
    EXPECT_TRUE(centre.origin.isApprox(camera.position));
    EXPECT_NEAR((centre.direction - Vector3(0, 0, -1)).norm(), 0.0, 1e-15);
    // 90 degrees vertically: the top edge is 45 degrees up; x to the right, y down.
    const Ray top = camera.generate_ray(0.5, 0.0, 2.0);
    EXPECT_NEAR(top.direction.y(), std::sqrt(0.5), 1e-15);
    const Ray right = camera.generate_ray(1.0, 0.5, 2.0);
    EXPECT_NEAR(std::atan2(right.direction.x(), -right.direction.z()), std::atan(2.0), 1e-14);
    EXPECT_NEAR(right.direction.norm(), 1.0, 1e-15);
}

TEST(Camera, OrthographicRaysAreParallelAndSpanTheHeight) {
    Camera camera;
    camera.projection = Camera::Projection::Orthographic;
    camera.position = Point3(0, 0, 5);
    camera.look_at = Point3(0, 0, 0);
    camera.orthographic_height = 4.0;
    const Ray top_left = camera.generate_ray(0.0, 0.0, 1.5);
    const Ray bottom_right = camera.generate_ray(1.0, 1.0, 1.5);
    EXPECT_TRUE(top_left.direction.isApprox(Vector3(0, 0, -1)));
    EXPECT_TRUE(bottom_right.direction.isApprox(Vector3(0, 0, -1)));
    EXPECT_TRUE(top_left.origin.isApprox(Point3(-3, 2, 5)));
    EXPECT_TRUE(bottom_right.origin.isApprox(Point3(3, -2, 5)));
}

TEST(Camera, ValidateNamesTheBadField) {
    Camera camera;
    camera.look_at = camera.position;
    EXPECT_THROW(camera.validate(), InvalidParameter);
    camera = Camera{};
    camera.up = Vector3(0, 0, 1);  // parallel to the view direction
    EXPECT_THROW(camera.validate(), InvalidParameter);
    camera = Camera{};
    camera.vertical_fov_degrees = 180.0;
    try {
        camera.validate();
        FAIL() << "no exception";
    } catch (const InvalidParameter& error) {
        EXPECT_NE(std::string(error.what()).find("vertical_fov_degrees"), std::string::npos);
    }
    EXPECT_NO_THROW(Camera{}.validate());
}

}  // namespace
}  // namespace csgrt
