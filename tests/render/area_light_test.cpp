#include "csgrt/render/lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "csgrt/core/error.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/renderer.h"
#include "render/scenes.h"

namespace csgrt {
namespace {

// The floor y = 0, white (albedo 1), seen at `target` by a 1-pixel render from below every
// occluder: its radiance is E / pi for the irradiance E the lights give there.
Vector3 floor_radiance(Scene scene, const Point3& target) {
    test::set_view(scene, target + Vector3(0.0, 0.5, 2.0), target);
    scene.commit();
    RenderSettings settings = test::settings_of_size(1, 1);
    const RenderResult result = render(scene, settings);
    const Pixel& pixel = result.image.at(0, 0);
    return Vector3(pixel.red, pixel.green, pixel.blue);
}

Scene white_floor() {
    Scene scene;
    const auto white = scene.add_material(Material{"white", Vector3::Constant(1.0)});
    scene.add_object(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 1, 0)), white);
    return scene;
}

// Point-to-rectangle view factor from a point beneath one corner of an a x b rectangle at
// height h, parallel to the receiver (Howell's catalogue of configuration factors, B-3):
// E = pi L F.
double corner_view_factor(double a, double b, double h) {
    const double x = a / h;
    const double y = b / h;
    const double sx = std::sqrt(1.0 + x * x);
    const double sy = std::sqrt(1.0 + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2.0 * kPi);
}

// The estimator is sum_i A f(x_i) / N over N equal strata, one jittered sample each, and the
// exact irradiance is sum_i A mean_i(f) / N: the two differ by at most A max|grad f| diam,
// diam the largest stratum's diameter on the light. For f = L h^2 / (h^2 + r^2)^2 (a light
// parallel to the receiver, r the distance from the foot of the normal),
// |df/dr| = 4 L h^2 r / (h^2 + r^2)^3 <= 4 L h^2 r* / (h^2 + r*^2)^3 at r* = h / sqrt(5).
double parallel_gradient_bound(double radiance, double h) {
    const double r = h / std::sqrt(5.0);
    return 4.0 * radiance * h * h * r / std::pow(h * h + r * r, 3);
}

TEST(RectangleLight, IrradianceBelowItsCentreIsTheViewFactors) {
    const double h = 1.0;
    const double radiance = 3.0;
    Scene scene = white_floor();
    RectangleLight light;
    light.corner = Point3(-0.5, h, -0.75);
    light.edge_u = Vector3(1.0, 0.0, 0.0);
    light.edge_v = Vector3(0.0, 0.0, 1.5);  // u x v = (0, -1.5, 0): it shines down
    light.radiance = Vector3::Constant(radiance);
    light.samples = 1024;  // 32 x 32 strata
    scene.add_light(light);
    const double exact = kPi * radiance * 4.0 * corner_view_factor(0.5, 0.75, h);
    const double diameter = std::hypot(1.0 / 32.0, 1.5 / 32.0);
    const double bound = 1.5 * parallel_gradient_bound(radiance, h) * diameter;
    const Vector3 seen = floor_radiance(scene, Point3(0, 0, 0));
    EXPECT_NEAR(seen.x() * kPi, exact, bound);
    EXPECT_GT(seen.x(), 0.5 * exact / kPi);  // the bound is not so loose as to say nothing
    EXPECT_LT(bound, 0.1 * exact);

    // Turned over, it shines up and the floor gets nothing.
    Scene flipped = white_floor();
    std::swap(light.edge_u, light.edge_v);
    flipped.add_light(light);
    EXPECT_EQ(floor_radiance(flipped, Point3(0, 0, 0)), Vector3::Zero());
}

TEST(DiskLight, IrradianceBelowItsCentreIsPiLRSquaredOverHSquaredPlusRSquared) {
    // E = pi L R^2 / (h^2 + R^2) for a disk of radius R at height h facing the point.
    const double h = 2.0;
    const double radius = 1.0;
    const double radiance = 5.0;
    Scene scene = white_floor();
    scene.add_light(DiskLight{Point3(0, h, 0), Vector3(0, -1, 0), radius,
                              Vector3::Constant(radiance), 4096});
    const double exact = kPi * radiance * radius * radius / (h * h + radius * radius);
    // Concentric map: a displacement du in the square moves the disk point by at most
    // (1 + pi / 2) 2 R |du| (radius and angle terms), so a stratum of diagonal sqrt(2) / 64
    // has diameter <= (1 + pi / 2) 2 R sqrt(2) / 64 on the disk.
    const double diameter = (1.0 + kPi / 2.0) * 2.0 * radius * std::sqrt(2.0) / 64.0;
    const double bound = kPi * radius * radius * parallel_gradient_bound(radiance, h) * diameter;
    EXPECT_NEAR(floor_radiance(scene, Point3(0, 0, 0)).x() * kPi, exact, bound);
    EXPECT_LT(bound, 0.1 * exact);
}

TEST(SphereLight, IrradianceFacingItIsPiLRSquaredOverDSquared) {
    // A ball of radius r at distance d on the normal: E = pi L sin^2(theta_max) = pi L r^2/d^2.
    const double d = 3.0;
    const double r = 1.0;
    const double radiance = 4.0;
    Scene scene = white_floor();
    scene.add_light(SphereLight{Point3(0, d, 0), r, Vector3::Constant(radiance), 1024});
    const double exact = kPi * radiance * r * r / (d * d);
    // Each sample brings L Omega cos(theta) / N with cos(theta) = 1 - u_x (1 - cos_max): over a
    // stratum (32 columns in u_x) cos(theta) varies by (1 - cos_max) / 32 at most.
    const double cos_max = std::sqrt(1.0 - r * r / (d * d));
    const double bound = radiance * kTwoPi * (1.0 - cos_max) * (1.0 - cos_max) / 32.0;
    EXPECT_NEAR(floor_radiance(scene, Point3(0, 0, 0)).x() * kPi, exact, bound + 1e-6 * exact);
    // A point inside the ball is not lit by it.
    Scene inside = white_floor();
    inside.add_light(SphereLight{Point3(0, 0.5, 0), 1.0, Vector3::Constant(radiance), 16});
    EXPECT_EQ(floor_radiance(inside, Point3(0, 0, 0)), Vector3::Zero());
}

TEST(RectangleLight, PenumbraBehindAnEdgeHasTheWidthSimilarTrianglesGive) {
    // A light of width w = 1 (x in [-0.5, 0.5]) at height H = 2 and an opaque sheet at height
    // h = 1 covering x < 0. A floor point x sees the light at s through the sheet's plane at
    // (x + s) h / H... blocked when x + (s - x) h / H < 0: fully dark for x < -w h / (2 (H - h))
    // and fully lit for x > w h / (2 (H - h)): a penumbra of width w h / (H - h) = 1. Strata
    // are 64 columns wide across x, each projecting to w h / (64 (H - h)) on the floor: inside
    // the penumbra, farther than that from its edges, some samples are blocked and some not.
    const double w = 1.0;
    const double height_light = 2.0;
    const double height_edge = 1.0;
    RectangleLight light;
    light.corner = Point3(-0.5 * w, height_light, -0.5);
    light.edge_u = Vector3(w, 0.0, 0.0);
    light.edge_v = Vector3(0.0, 0.0, 1.0);
    light.radiance = Vector3::Constant(2.0);
    light.samples = 4096;
    Scene open = white_floor();
    open.add_light(light);
    Scene shadowed = white_floor();
    shadowed.add_light(light);
    // The sheet ends at z = 0.5: the camera's rays (from z = 2, height 0.5) pass under it and
    // the shadow rays from z = 0 cross its plane within |z| <= 0.25.
    shadowed.add_object(std::make_shared<Rectangle>(Point3(-10, height_edge, -10),
                                                    Vector3(10, 0, 0), Vector3(0, 0, 10.5)));
    const double half_width = 0.5 * w * height_edge / (height_light - height_edge);
    const double stratum = w * height_edge / (64.0 * (height_light - height_edge));
    for (int i = -30; i <= 30; ++i) {
        const double x = 0.025 * i;
        const Point3 target(x, 0, 0);
        const double lit = floor_radiance(open, target).x();
        const double seen = floor_radiance(shadowed, target).x();
        ASSERT_GT(lit, 0.0);
        if (x < -half_width - 1e-9) {
            EXPECT_EQ(seen, 0.0) << x;
        } else if (x > half_width + 1e-9) {
            EXPECT_NEAR(seen, lit, 1e-6 * lit) << x;
        } else if (std::abs(x) < half_width - stratum) {
            EXPECT_GT(seen, 0.0) << x;
            EXPECT_LT(seen, lit * (1.0 - 1e-3)) << x;
        }
    }
}

TEST(AreaLight, RendersAreTheSameWhateverTheThreads) {
    Scene scene = white_floor();
    scene.add_object(std::make_shared<Sphere>(Point3(0, 0.5, 0), 0.5));
    scene.add_light(RectangleLight{Point3(-1, 3, -1), Vector3(2, 0, 0), Vector3(0, 0, 2),
                                   Vector3::Constant(5.0), 9});
    scene.add_light(DiskLight{Point3(2, 2, 0), Vector3(-1, -1, 0), 0.5, Vector3::Constant(3.0), 7});
    scene.add_light(SphereLight{Point3(-2, 2, 1), 0.3, Vector3::Constant(20.0), 16});
    test::set_view(scene, Point3(0, 2, 4), Point3(0, 0.3, 0));
    scene.commit();
    RenderSettings settings = test::settings_of_size(24, 16);
    settings.tile_size = 4;
    settings.samples_per_pixel = 2;
    settings.threads = 1;
    const RenderResult one = render(scene, settings);
    settings.threads = 2;
    const RenderResult two = render(scene, settings);
    const RenderResult again = render(scene, settings);
    double total = 0.0;
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            const Pixel& a = one.image.at(x, y);
            EXPECT_EQ(std::memcmp(&a, &two.image.at(x, y), sizeof(Pixel)), 0) << x << " " << y;
            EXPECT_EQ(std::memcmp(&a, &again.image.at(x, y), sizeof(Pixel)), 0) << x << " " << y;
            total += a.red;
        }
    }
    EXPECT_GT(total, 0.0);
}

TEST(AreaLight, BadLightsAreRefused) {
    Scene scene;
    EXPECT_THROW(scene.add_light(RectangleLight{.samples = 0}), InvalidParameter);
    EXPECT_THROW(scene.add_light(RectangleLight{.samples = kMaxAreaLightSamples + 1}),
                 InvalidParameter);
    EXPECT_THROW(scene.add_light(RectangleLight{.edge_v = Vector3(2, 0, 0)}), InvalidParameter);
    EXPECT_THROW(scene.add_light(DiskLight{.radius = 0.0}), InvalidParameter);
    EXPECT_THROW(scene.add_light(DiskLight{.normal = Vector3::Zero()}), InvalidParameter);
    EXPECT_THROW(scene.add_light(SphereLight{.radius = -1.0}), InvalidParameter);
    EXPECT_THROW(scene.add_light(SphereLight{.radiance = Vector3(-1, 0, 0)}), InvalidParameter);
    EXPECT_TRUE(scene.lights().empty());
}

TEST(AreaLight, SceneFileLightsLoad) {
    const Scene scene = load_scene_from_string(R"({
        "lights": [
          {"type": "rectangle", "corner": [-1, 4, -1], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2],
           "radiance": 6, "samples": 25},
          {"type": "disk", "center": [0, 3, 0], "normal": [0, -1, 0], "radius": 0.5},
          {"type": "sphere", "center": [1, 2, 3], "radius": 0.25, "radiance": [1, 2, 3]}
        ],
        "objects": []
    })", "lights.json");
    ASSERT_EQ(scene.lights().size(), 3u);
    const auto& rectangle = std::get<RectangleLight>(scene.lights()[0]);
    EXPECT_EQ(rectangle.edge_v, Vector3(0, 0, 2));
    EXPECT_EQ(rectangle.radiance, Vector3::Constant(6.0));
    EXPECT_EQ(rectangle.samples, 25);
    const auto& disk = std::get<DiskLight>(scene.lights()[1]);
    EXPECT_EQ(disk.radius, 0.5);
    EXPECT_EQ(disk.samples, kDefaultAreaLightSamples);
    const auto& sphere = std::get<SphereLight>(scene.lights()[2]);
    EXPECT_EQ(sphere.centre, Point3(1, 2, 3));
    EXPECT_EQ(sphere.radiance, Vector3(1, 2, 3));
}

}  // namespace
}  // namespace csgrt
