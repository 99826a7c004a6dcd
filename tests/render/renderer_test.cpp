#include "csgrt/render/renderer.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <vector>

#include "csgrt/core/error.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/scene.h"
#include "render/scenes.h"

namespace csgrt {
namespace {

/// A camera ray computed here from the camera's definition (not with Camera::generate_ray):
/// film point (x, y) in [0, 1]^2, x right, y down, in long double.
struct TestRay {
    Eigen::Matrix<long double, 3, 1> origin;
    Eigen::Matrix<long double, 3, 1> direction;  // unit
};

TestRay camera_ray(const Camera& camera, long double x, long double y, long double aspect) {
    using V = Eigen::Matrix<long double, 3, 1>;
    const V position = camera.position.cast<long double>();
    const V forward = (camera.look_at.cast<long double>() - position).normalized();
    const V right = forward.cross(camera.up.cast<long double>()).normalized();
    const V up = right.cross(forward);
    const long double fx = (2 * x - 1) * aspect, fy = 1 - 2 * y;
    if (camera.projection == Camera::Projection::Pinhole) {
        const long double h = std::tan((long double)camera.vertical_fov_degrees * kPi / 360.0L);
        return {position, (forward + h * (fx * right + fy * up)).normalized()};
    }
    const long double h = 0.5L * camera.orthographic_height;
    return {position + h * (fx * right + fy * up), forward};
}

/// The nearer root of a ray (unit direction) with a sphere, or -1 for a miss; `margin`
/// receives how far the ray is from grazing (discriminant / r^2), to skip silhouette pixels.
long double sphere_root(const TestRay& ray, const Point3& centre, double radius,
                        long double& margin) {
    const auto f = ray.origin - centre.cast<long double>();
    const long double b = f.dot(ray.direction);
    const long double r2 = (long double)radius * radius;
    const long double discriminant = b * b - (f.squaredNorm() - r2);
    margin = std::min(margin, std::abs(discriminant) / r2);
    if (discriminant < 0) return -1;
    const long double t = -b - std::sqrt(discriminant);
    return t >= 0 ? t : -1;
}

struct SphereSpec {
    Point3 centre;
    double radius;
};

TEST(Render, CentreDepthIsTheAnalyticDistanceToASphere) {
    const Point3 centre(0.3, -0.2, -1.0);
    for (const Point3& position : {Point3(0.3, -0.2, 4.0), Point3(3.0, 2.0, 4.0)}) {
        for (auto projection : {Camera::Projection::Pinhole, Camera::Projection::Orthographic}) {
            Scene scene;
            scene.add_object(std::make_shared<Sphere>(centre, 0.7));
            Camera camera;
            camera.projection = projection;
            camera.position = position;
            camera.look_at = centre;
            scene.set_camera(camera);
            scene.commit();
            // An odd size puts the centre pixel's ray exactly on the line to look_at.
            const Image image = render(scene, test::settings_of_size(63, 41)).image;
            const Pixel& pixel = image.at(31, 20);
            const double expected = (position - centre).norm() - 0.7;
            // Depth is stored as float: within one float rounding (2^-24 relative), doubled.
            EXPECT_NEAR(pixel.depth, expected, expected * 0x1.0p-23);
            EXPECT_EQ(pixel.object_id, 0u);
            const Vector3 normal = (position - centre).normalized();
            EXPECT_NEAR(pixel.normal_x, normal.x(), 1e-6);
            EXPECT_NEAR(pixel.normal_y, normal.y(), 1e-6);
            EXPECT_NEAR(pixel.normal_z, normal.z(), 1e-6);
        }
    }
}

TEST(Render, EveryPixelsIdDepthAndNormalMatchAnAnalyticTraceOfTheSpheres) {
    const std::vector<SphereSpec> spheres = {{Point3(-1.2, 0.3, 0.0), 0.8},
                                             {Point3(0.4, -0.2, -1.5), 1.1},
                                             {Point3(1.3, 0.8, 0.8), 0.5}};
    for (auto projection : {Camera::Projection::Pinhole, Camera::Projection::Orthographic}) {
        Scene scene;
        for (const SphereSpec& s : spheres)
            scene.add_object(std::make_shared<Sphere>(s.centre, s.radius));
        Camera camera;
        camera.projection = projection;
        camera.position = Point3(0.5, 1.0, 6.0);
        camera.look_at = Point3(0.0, 0.0, -0.3);
        camera.orthographic_height = 4.5;
        scene.set_camera(camera);
        scene.commit();
        const int width = 80, height = 60;
        const Image image = render(scene, test::settings_of_size(width, height)).image;
        int compared = 0, background = 0;
        for (int y = 0; y < height; ++y) {
            for (int x = 0; x < width; ++x) {
                const TestRay ray = camera_ray(scene.camera(), (x + 0.5L) / width,
                                               (y + 0.5L) / height, (long double)width / height);
                long double best = -1, margin = 1;
                std::uint32_t best_id = kNoIndex;
                for (std::uint32_t id = 0; id < spheres.size(); ++id) {
                    const long double t =
                        sphere_root(ray, spheres[id].centre, spheres[id].radius, margin);
                    if (t >= 0 && (best < 0 || t < best)) {
                        best = t;
                        best_id = id;
                    }
                }
                if (margin < 1e-6) continue;  // grazing: either answer is right
                const Pixel& pixel = image.at(x, y);
                ASSERT_EQ(pixel.object_id, best_id) << "pixel " << x << ", " << y;
                if (best_id == kNoIndex) {
                    ++background;
                    EXPECT_EQ(pixel.depth, std::numeric_limits<float>::infinity());
                    EXPECT_EQ(pixel.normal_x, 0.0f);
                    EXPECT_EQ(pixel.alpha, 0.0f);
                    EXPECT_EQ(pixel.red, 0.0f);
                    continue;
                }
                ++compared;
                // Float storage (2^-24) dominates the double root's error.
                EXPECT_NEAR(pixel.depth, (double)best, (double)best * 0x1.0p-22);
                const auto point = ray.origin + best * ray.direction;
                const auto normal = (point - spheres[best_id].centre.cast<long double>()) /
                                    (long double)spheres[best_id].radius;
                const Vector3 stored(pixel.normal_x, pixel.normal_y, pixel.normal_z);
                // Unit length to float precision, and the analytic normal.
                EXPECT_NEAR(stored.norm(), 1.0, 4 * 0x1.0p-24);
                EXPECT_LT((stored - normal.cast<double>()).norm(), 1e-5);
                EXPECT_EQ(pixel.alpha, 1.0f);
            }
        }
        EXPECT_GT(compared, 1000);
        EXPECT_GT(background, 500);
    }
}

/// The unit sphere at the origin in one material of colour `albedo`, seen by the default camera
/// from (0, 0, `distance`): the centre pixel shows the point (0, 0, 1), facing the camera. Not
/// committed, so a test can still add lights.
Scene unit_sphere_seen_from(double distance, const Vector3& albedo) {
    Scene scene;
    scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0),
                     scene.add_material(Material{"m", albedo}));
    Camera camera;
    camera.position = Point3(0, 0, distance);
    scene.set_camera(camera);
    return scene;
}

/// `pixel`'s colour is `expected` to the rounding of its half storage (2^-11 relative), doubled;
/// `label` names the pixel.
void expect_half_colour(const Pixel& pixel, const Vector3& expected, const char* label) {
    EXPECT_NEAR(pixel.red, expected.x(), expected.x() * 0x1.0p-10) << label;
    EXPECT_NEAR(pixel.green, expected.y(), expected.y() * 0x1.0p-10) << label;
    EXPECT_NEAR(pixel.blue, expected.z(), expected.z() * 0x1.0p-10) << label;
}

TEST(Render, LambertShadingOfPointAndDirectionalLightsMatchesTheFormula) {
    const Vector3 albedo(0.6, 0.5, 0.25);
    Scene scene = unit_sphere_seen_from(5.0, albedo);
    const Vector3 intensity(40, 30, 20), radiance(0.5, 1.0, 1.5);
    scene.add_light(PointLight{Point3(2, 3, 4), intensity});
    scene.add_light(DirectionalLight{Vector3(0, 0, -2), radiance});
    scene.commit();
    const RenderResult result = render(scene, test::settings_of_size(31, 31));
    // Centre pixel: the hit is (0, 0, 1) with normal +z. The point light is at distance^2 22
    // with cosine 3 / sqrt(22); the directional light shines straight at the surface.
    const Vector3 expected =
        albedo.cwiseProduct(intensity / 22.0 * (3.0 / std::sqrt(22.0)) + radiance) / kPi;
    const Pixel& pixel = result.image.at(15, 15);
    expect_half_colour(pixel, expected, "centre pixel");
    EXPECT_EQ(pixel.alpha, 1.0f);
    // Both lights face every visible point near the centre; all get two shadow rays, fewer
    // near the rim, where the lights are behind the surface.
    EXPECT_GT(result.stats.shadow_rays, 0u);
    EXPECT_LE(result.stats.shadow_rays, 2 * result.stats.primary_rays);
}

TEST(Render, HardShadowOfASphereOnAPlaneIsExactlyWhereTheSphereBlocksTheLight) {
    Scene scene;
    scene.add_object(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 1, 0)));  // albedo 0.8
    scene.add_object(std::make_shared<Sphere>(Point3(0, 1, 0), 0.5));
    scene.add_light(DirectionalLight{Vector3(0, -1, 0), Vector3(1, 1, 1)});
    test::set_view(scene, Point3(0, 4, 6), Point3(0, 0, 0));
    scene.commit();
    const int width = 96, height = 72;
    const Image image = render(scene, test::settings_of_size(width, height)).image;
    const double lit = 0.8 / kPi;  // albedo / pi * E * cos 0
    int shadowed = 0, unshadowed = 0;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const Pixel& pixel = image.at(x, y);
            if (pixel.object_id != 0) continue;
            const TestRay ray = camera_ray(scene.camera(), (x + 0.5L) / width, (y + 0.5L) / height,
                                           (long double)width / height);
            const auto point = ray.origin + (long double)pixel.depth * ray.direction;
            // Straight down: the point is in shadow when it lies under the sphere's disc.
            const long double from_axis = std::hypot(point.x(), point.z());
            if (std::abs(from_axis - 0.5L) < 1e-3L) continue;  // on the shadow's edge
            if (from_axis < 0.5L) {
                ++shadowed;
                EXPECT_EQ(pixel.red, 0.0f) << "pixel " << x << ", " << y << " should be dark";
            } else {
                ++unshadowed;
                // No acne: every lit ground pixel has the full value (half-rounded).
                EXPECT_NEAR(pixel.red, lit, lit * 0x1.0p-10) << "pixel " << x << ", " << y;
            }
        }
    }
    EXPECT_GT(shadowed, 50);
    EXPECT_GT(unshadowed, 2000);
}

TEST(Render, ASceneWithoutLightsIsLitFromTheEyeAndCastsNoShadowRays) {
    const Vector3 albedo(0.3, 0.6, 0.9);
    Scene scene = unit_sphere_seen_from(4.0, albedo);
    scene.commit();
    const RenderResult result = render(scene, test::settings_of_size(21, 21, 4));
    EXPECT_EQ(result.stats.shadow_rays, 0u);
    // The centre pixel's samples leave the camera at most half a pixel diagonal from the axis,
    // alpha <= tan(20 deg) * 2 / 21 * sqrt(2) / 2 = 0.0245 rad; with the camera 3 radii from
    // the surface the normal turns by about 3 alpha, so n . v >= cos(4 alpha) = 0.9952.
    const Pixel& pixel = result.image.at(10, 10);
    for (int c = 0; c < 3; ++c) {
        const float value = c == 0 ? pixel.red : c == 1 ? pixel.green : pixel.blue;
        EXPECT_LE(value, albedo[c] * (1.0 + 0x1.0p-10));
        EXPECT_GE(value, albedo[c] * 0.995);
    }
    // With one sample, the centre ray is on the axis: exactly the albedo (half-rounded).
    // A copy: the RenderResult is a temporary that dies at the end of this statement.
    const Pixel centre = render(scene, test::settings_of_size(21, 21, 1)).image.at(10, 10);
    expect_half_colour(centre, albedo, "centre pixel, one sample");
}

TEST(Render, CountsPrimaryAndShadowRays) {
    Scene scene;
    scene.add_object(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 0, 1)));
    scene.add_light(DirectionalLight{Vector3(0, 0, -1), Vector3(1, 1, 1)});
    Camera camera;
    camera.position = Point3(0, 0, 3);
    scene.set_camera(camera);
    scene.commit();
    // Every camera ray hits the plane, which faces the light: one shadow ray per colour sample.
    const RenderResult one = render(scene, test::settings_of_size(10, 7, 1));
    EXPECT_EQ(one.stats.primary_rays, 70u);
    EXPECT_EQ(one.stats.shadow_rays, 70u);
    const RenderResult nine = render(scene, test::settings_of_size(10, 7, 9));
    EXPECT_EQ(nine.stats.primary_rays, 70u * 9 + 70u);  // samples plus the AOV centre ray
    EXPECT_EQ(nine.stats.shadow_rays, 70u * 9);
    EXPECT_GT(nine.stats.seconds, 0.0);
}

TEST(Render, StratifiedSamplesEstimateTheCoverageOfAnEdge) {
    // An orthographic camera with one world unit per pixel; a box edge at x = 0.3 crosses
    // pixel column 8 (x in [0, 1]) 30% of the way in, so 70% of it is covered.
    Scene scene;
    scene.add_object(std::make_shared<Box>(Point3(0.3, -100, -1), Point3(100, 100, 0)));
    Camera camera;
    camera.projection = Camera::Projection::Orthographic;
    camera.position = Point3(0, 0, 10);
    camera.orthographic_height = 16.0;
    scene.set_camera(camera);
    scene.commit();
    const Image image = render(scene, test::settings_of_size(16, 16, 16)).image;
    double sum = 0.0;
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 8; ++x) EXPECT_EQ(image.at(x, y).alpha, 0.0f);
        for (int x = 9; x < 16; ++x) EXPECT_EQ(image.at(x, y).alpha, 1.0f);
        // 4 x 4 strata: the first column of strata is outside, the last two inside, and each
        // of the 4 samples in the second is inside with probability 0.8: 8 to 12 of 16.
        const float alpha = image.at(8, y).alpha;
        EXPECT_GE(alpha, 8.0f / 16.0f);
        EXPECT_LE(alpha, 12.0f / 16.0f);
        sum += alpha;
    }
    // Each pixel's estimate has standard deviation sqrt(4 * 0.8 * 0.2) / 16 = 0.05; the mean
    // of 16 has 0.0125. Allow four.
    EXPECT_NEAR(sum / 16.0, 0.7, 0.05);
}

SceneConfig structure(std::string_view name) {
    SceneConfig config;
    config.accelerator = std::string(name);
    return config;
}

bool same_pixels(const Image& a, const Image& b, bool compare_cost) {
    if (a.width() != b.width() || a.height() != b.height()) return false;
    for (std::size_t i = 0; i < a.pixel_count(); ++i) {
        const Pixel& p = a.pixels()[i];
        const Pixel& q = b.pixels()[i];
        if (p.red != q.red || p.green != q.green || p.blue != q.blue || p.alpha != q.alpha ||
            p.depth != q.depth || p.normal_x != q.normal_x || p.normal_y != q.normal_y ||
            p.normal_z != q.normal_z || p.object_id != q.object_id ||
            (compare_cost && p.cost != q.cost)) {
            return false;
        }
    }
    return true;
}

TEST(Render, OutputDoesNotDependOnThreadsOrTiles) {
    Scene scene = test::spheres_on_a_plane();
    scene.commit();
    RenderSettings settings = test::settings_of_size(53, 37, 4);
    settings.threads = 1;
    const RenderResult one = render(scene, settings);
    for (int threads : {2, 3}) {
        for (int tile : {16, 5}) {
            settings.threads = threads;
            settings.tile_size = tile;
            const RenderResult many = render(scene, settings);
            EXPECT_TRUE(same_pixels(one.image, many.image, true))
                << threads << " threads, tiles of " << tile;
            EXPECT_EQ(one.stats.shadow_rays, many.stats.shadow_rays);
        }
    }
    // The seed does change the jitter, so the comparison above can fail.
    settings.seed = 1;
    EXPECT_FALSE(same_pixels(one.image, render(scene, settings).image, true));
}

// The renderer's image is not filled before rendering (Image::for_writing): every pixel must
// be written whole. glibc's M_PERTURB fills each new heap block with the complement of its
// byte, so the image below starts as garbage (0xa5 bytes: NaNs and ids that are no object);
// it must come out byte for byte as the render into whatever the heap held before.
TEST(Render, EveryPixelIsWrittenWholeWhateverTheImagesMemoryHeld) {
    Scene scene = test::spheres_on_a_plane();
    scene.commit();
    // 40 x 30 pixels of 52 bytes: a heap block well below glibc's mmap threshold (128 KiB),
    // which M_PERTURB reaches (mapped blocks come zeroed from the kernel).
    const RenderSettings settings = test::settings_of_size(40, 30, 1);
    const Image reference = render(scene, settings).image;
    // Under ASan and TSan, whose allocators ignore mallopt, ASan's own fill of new blocks
    // (0xbe, their first 4 KiB) is what the image starts as.
    mallopt(M_PERTURB, 0x5a);
    const Image image = render(scene, settings).image;
    mallopt(M_PERTURB, 0);
    ASSERT_EQ(image.pixel_count(), reference.pixel_count());
    static_assert(sizeof(Pixel) == 13 * sizeof(float), "Pixel has no padding to compare");
    int background = 0;
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        const Pixel& pixel = image.pixels()[i];
        ASSERT_EQ(std::memcmp(&pixel, &reference.pixels()[i], sizeof(Pixel)), 0) << "pixel " << i;
        if (pixel.object_id == kNoIndex) {
            ++background;
            EXPECT_EQ(pixel.depth, std::numeric_limits<float>::infinity());
            EXPECT_EQ(pixel.normal_x, 0.0f);
            EXPECT_EQ(pixel.alpha, 0.0f);
        }
    }
    EXPECT_GT(background, 0);  // the camera sees past the plane's horizon
}

TEST(Render, EveryStructureGivesTheSameImages) {
    for (int which = 0; which < 2; ++which) {
        Scene scene = which == 0 ? test::spheres_on_a_plane() : test::sphere_lattice(5);
        scene.commit(structure("brute"));
        const Image reference = render(scene, test::settings_of_size(48, 36, 4)).image;
        for (std::string_view name : accelerator_names()) {
            scene.commit(structure(name));
            const Image image = render(scene, test::settings_of_size(48, 36, 4)).image;
            // Colour, depth, normal and id pixel-exact: structures return the same hits.
            EXPECT_TRUE(same_pixels(reference, image, false)) << name;
        }
    }
}

TEST(Render, CostIsLowerWithAHierarchyThanWithBruteForce) {
    Scene scene = test::sphere_lattice(8);  // 512 spheres
    scene.commit(structure("brute"));
    auto total_cost = [&] {
        double sum = 0.0;
        const Image image = render(scene, test::settings_of_size(40, 30)).image;
        for (const Pixel& pixel : image.pixels()) sum += pixel.cost;
        return sum;
    };
    const double brute = total_cost();
    // Brute force tests every sphere on every camera ray, and each test is a root solve.
    EXPECT_EQ(brute, 40.0 * 30.0 * 512.0 * 2.0);
    int compared = 0;
    for (std::string_view name : accelerator_names()) {
        if (name == "brute") continue;
        scene.commit(structure(name));
        EXPECT_LT(total_cost(), 0.5 * brute) << name;
        ++compared;
    }
    if (compared == 0) GTEST_SKIP() << "only brute force is registered with make_accelerator";
}

TEST(Render, ReportsProgressUpToOne) {
    Scene scene = test::spheres_on_a_plane();
    scene.commit();
    RenderSettings settings = test::settings_of_size(40, 20);
    settings.tile_size = 8;  // 5 x 3 tiles
    std::mutex mutex;
    std::vector<double> reports;
    settings.progress = [&](double fraction) {
        std::lock_guard lock(mutex);
        reports.push_back(fraction);
    };
    render(scene, settings);
    ASSERT_EQ(reports.size(), 15u);
    std::sort(reports.begin(), reports.end());
    EXPECT_DOUBLE_EQ(reports.front(), 1.0 / 15.0);
    EXPECT_DOUBLE_EQ(reports.back(), 1.0);
}

TEST(Render, RejectsBadSettingsAndUncommittedScenes) {
    Scene scene = test::spheres_on_a_plane();
    EXPECT_THROW(render(scene, test::settings_of_size(8, 8)), InvalidParameter);  // not committed
    scene.commit();
    EXPECT_NO_THROW(render(scene, test::settings_of_size(1, 1)));
    EXPECT_THROW(render(scene, test::settings_of_size(0, 8)), InvalidParameter);
    EXPECT_THROW(render(scene, test::settings_of_size(8, -1)), InvalidParameter);
    EXPECT_THROW(render(scene, test::settings_of_size(kMaxImageSize + 1, 8)), InvalidParameter);
    EXPECT_THROW(render(scene, test::settings_of_size(8, 8, 0)), InvalidParameter);
    EXPECT_THROW(render(scene, test::settings_of_size(8, 8, kMaxSamplesPerPixel + 1)),
                 InvalidParameter);
    RenderSettings settings = test::settings_of_size(8, 8);
    settings.threads = -2;
    EXPECT_THROW(render(scene, settings), InvalidParameter);
    try {
        render(scene, test::settings_of_size(8, 20000));
        FAIL() << "no exception";
    } catch (const InvalidParameter& error) {
        EXPECT_NE(std::string(error.what()).find("height"), std::string::npos) << error.what();
    }
}

}  // namespace
}  // namespace csgrt
