#include "csgrt/render/materials.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "csgrt/core/error.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/painted.h"
#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/renderer.h"
#include "render/scenes.h"

namespace csgrt {
namespace {

TEST(Fresnel, NormalIncidenceIsTheSquaredIndexRatio) {
    // ((n - 1) / (n + 1))^2: 0.04 for glass, the same from either side.
    EXPECT_NEAR(fresnel_dielectric(1.0, 1.0, 1.5), 0.04, 1e-15);
    EXPECT_NEAR(fresnel_dielectric(1.0, 1.5, 1.0), 0.04, 1e-15);
    EXPECT_NEAR(fresnel_dielectric(1.0, 1.0, 1.333), std::pow(0.333 / 2.333, 2), 1e-15);
    EXPECT_EQ(fresnel_dielectric(0.7, 1.5, 1.5), 0.0);  // no interface, no reflection
}

TEST(Fresnel, GrazingIncidenceAndTotalInternalReflectionReflectEverything) {
    EXPECT_NEAR(fresnel_dielectric(0.0, 1.0, 1.5), 1.0, 1e-15);
    EXPECT_GT(fresnel_dielectric(1e-3, 1.0, 1.5), 0.99);
    // From glass, beyond the critical angle asin(1 / 1.5) = 41.8 degrees: everything.
    const double critical = std::asin(1.0 / 1.5);
    EXPECT_EQ(fresnel_dielectric(std::cos(critical + 1e-6), 1.5, 1.0), 1.0);
    EXPECT_LT(fresnel_dielectric(std::cos(critical - 1e-3), 1.5, 1.0), 1.0);
}

TEST(Fresnel, BrewstersAngleReflectsOnlyTheSPolarisedHalf) {
    // At tan(theta) = n the p reflectance vanishes and theta_i + theta_t = 90 degrees, so
    // R = Rs / 2 with Rs = ((cos_i - n cos_t) / (cos_i + n cos_t))^2 and cos_t = sin_i.
    const double n = 1.5;
    const double theta = std::atan(n);
    const double rs = std::pow(
        (std::cos(theta) - n * std::sin(theta)) / (std::cos(theta) + n * std::sin(theta)), 2);
    EXPECT_NEAR(fresnel_dielectric(std::cos(theta), 1.0, n), 0.5 * rs, 1e-14);
}

TEST(Refract, ObeysSnellsLawAndReportsTotalInternalReflection) {
    const Normal3 normal(0, 1, 0);
    for (double degrees : {0.0, 10.0, 30.0, 60.0, 89.0}) {
        const double theta = degrees * kPi / 180.0;
        const Vector3 direction(std::sin(theta), -std::cos(theta), 0.0);
        const auto refracted = refract(direction, normal, 1.0 / 1.5);
        ASSERT_TRUE(refracted) << degrees;
        EXPECT_NEAR(refracted->norm(), 1.0, 1e-15);
        EXPECT_NEAR(1.5 * refracted->x(), std::sin(theta), 1e-15) << degrees;  // n1 sin = n2 sin
        EXPECT_LT(refracted->y(), 0.0);  // through the surface
        EXPECT_EQ(refracted->z(), 0.0);  // in the plane of incidence
    }
    const double beyond = std::asin(1.0 / 1.5) + 0.01;  // from glass, past the critical angle
    EXPECT_FALSE(refract(Vector3(std::sin(beyond), -std::cos(beyond), 0), normal, 1.5));
    EXPECT_EQ(reflect(Vector3(0.6, -0.8, 0), normal), Vector3(0.6, 0.8, 0));
}

TEST(PhongLobe, IntegratesToOneAtNormalViewing) {
    // (n + 2) / (2 pi) * integral over the hemisphere of cos^n(theta) cos(theta) = 1 when the
    // mirror direction is the normal; midpoint rule in theta (the azimuth integral is 2 pi).
    const Normal3 normal(0, 0, 1);
    for (double shininess : {1.0, 8.0, 64.0}) {
        const int steps = 200000;
        double sum = 0.0;
        for (int i = 0; i < steps; ++i) {
            const double theta = (i + 0.5) * (kPi / 2) / steps;
            const Vector3 to_light(std::sin(theta), 0.0, std::cos(theta));
            sum += phong_lobe(to_light, Vector3(0, 0, 1), normal, shininess) * std::cos(theta) *
                   std::sin(theta);
        }
        // Midpoint error ~ (pi/2)^3 / (24 steps^2) * max |f''|, below 1e-8 for these exponents.
        EXPECT_NEAR(sum * (kPi / 2) / steps * 2.0 * kPi, 1.0, 1e-6) << shininess;
    }
    EXPECT_EQ(phong_lobe(Vector3(0, 0, -1), Vector3(0, 0, 1), normal, 8.0), 0.0);
}

/// A one-pixel render through the camera's look-at direction.
Vector3 centre_pixel(const Scene& scene, RenderSettings settings, RenderStats* stats = nullptr) {
    settings.width = 1;
    settings.height = 1;
    const RenderResult result = render(scene, settings);
    if (stats) *stats = result.stats;
    const Pixel& pixel = result.image.at(0, 0);
    return Vector3(pixel.red, pixel.green, pixel.blue);
}

TEST(Mirror, ImagesAPointWhereGeometrySays) {
    // A mirror plane y = 0 and a grey ball at C = (0, 1, -3), no lights (eye light). The camera
    // at (0, 1, 3) looks at C's mirror image (0, -1, -3): the ray meets the mirror at the origin
    // and its reflection runs straight at C, meeting the ball head on, |n . v| = 1. So the
    // pixel is albedo * mirror = 0.5 * 0.8, to float rounding.
    Scene scene;
    Material mirror{"mirror", Vector3::Zero()};
    mirror.mirror = Vector3::Constant(0.8);
    const auto mirror_index = scene.add_material(mirror);
    const auto grey = scene.add_material(Material{"grey", Vector3::Constant(0.5)});
    scene.add_object(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 1, 0)), mirror_index);
    scene.add_object(std::make_shared<Sphere>(Point3(0, 1, -3), 0.5), grey);
    test::set_view(scene, Point3(0, 1, 3), Point3(0, -1, -3));
    scene.commit();
    RenderSettings settings;
    settings.background = Vector3(0.1, 0.2, 0.3);
    RenderStats stats;
    const Vector3 seen = centre_pixel(scene, settings, &stats);
    EXPECT_NEAR(seen.x(), 0.4, 1e-6);
    EXPECT_NEAR(seen.z(), 0.4, 1e-6);
    EXPECT_EQ(stats.secondary_rays, 1u);

    // Aimed at the image of a point beside the ball, the reflection misses: background, dimmed.
    test::set_view(scene, Point3(0, 1, 3), Point3(3, -1, -3));
    scene.commit();
    const Vector3 missed = centre_pixel(scene, settings);
    EXPECT_NEAR(missed.y(), 0.8 * 0.2, 1e-6);
    EXPECT_NEAR(missed.z(), 0.8 * 0.3, 1e-6);

    settings.max_depth = 0;  // no bounces: the mirror's own albedo, black
    EXPECT_EQ(centre_pixel(scene, settings), Vector3::Zero());
}

TEST(Glass, ASphereSeenThroughItsCentreLosesOnlyTheTruncatedPaths) {
    // Everything around is background B. At normal incidence every path stays on the axis and
    // ends in B except the one still inside the ball at the deepest bounce, of weight
    // (1 - R) R^(D - 1): the pixel is B (1 - (1 - R) R^(D - 1)), R = 0.04. Energy is neither
    // made nor lost at an interface, and none leaks through the surface.
    Scene scene;
    Material glass{"glass", Vector3::Zero()};
    glass.ior = 1.5;
    scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0), scene.add_material(glass));
    test::set_view(scene, Point3(0, 0, 5), Point3(0, 0, 0));
    scene.commit();
    RenderSettings settings;
    settings.background = Vector3(1.0, 0.5, 0.25);
    const double r = 0.04;
    for (int depth : {1, 2, 3, 6}) {
        settings.max_depth = depth;
        const double kept = 1.0 - (1.0 - r) * std::pow(r, depth - 1);
        const Vector3 seen = centre_pixel(scene, settings);
        // The pixel is stored as float: 1e-6 relative covers its rounding.
        EXPECT_NEAR(seen.x(), 1.0 * kept, 1e-6) << depth;
        EXPECT_NEAR(seen.z(), 0.25 * kept, 1e-6) << depth;
    }
}

TEST(Ambient, AddsAlbedoTimesAmbientUnshadowed) {
    Scene scene;
    const auto grey = scene.add_material(Material{"grey", Vector3::Constant(0.5)});
    scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0), grey);
    // A light behind the ball: the side the camera sees gets nothing but the ambient term.
    scene.add_light(PointLight{Point3(0, 0, -10), Vector3::Constant(100.0)});
    test::set_view(scene, Point3(0, 0, 5), Point3(0, 0, 0));
    scene.commit();
    RenderSettings settings;
    settings.ambient = Vector3(0.2, 0.4, 0.0);
    const Vector3 seen = centre_pixel(scene, settings);
    EXPECT_NEAR(seen.x(), 0.1, 1e-7);
    EXPECT_NEAR(seen.y(), 0.2, 1e-7);
    EXPECT_EQ(seen.z(), 0.0);
    settings.ambient = Vector3(-1, 0, 0);
    EXPECT_THROW(render(scene, settings), InvalidParameter);
    settings.ambient = Vector3::Zero();
    settings.max_depth = kMaxTraceDepth + 1;
    EXPECT_THROW(render(scene, settings), InvalidParameter);
}

TEST(Ambient, SceneAmbientAndBackgroundComeFromTheFileAndAddToTheSettings) {
    // A grey ball (albedo 0.5) lit only from behind, seen head on: its centre pixel is
    // albedo * (scene ambient + settings ambient); a camera aimed beside it sees
    // scene background + settings background. Pixels are floats: 1e-7 covers their rounding.
    const std::string text = R"({
        "ambient": [0.2, 0.4, 0.0],
        "background": [0.1, 0.2, 0.3],
        "materials": {"grey": {"albedo": 0.5}},
        "lights": [{"type": "point", "position": [0, 0, -10]}],
        "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
        "objects": [{"type": "sphere", "radius": 1, "material": "grey"}]
    })";
    Scene scene = load_scene_from_string(text, "ambient.json");
    EXPECT_EQ(scene.ambient(), Vector3(0.2, 0.4, 0.0));
    EXPECT_EQ(scene.background(), Vector3(0.1, 0.2, 0.3));
    scene.commit();
    RenderSettings settings;
    Vector3 seen = centre_pixel(scene, settings);
    EXPECT_NEAR(seen.x(), 0.1, 1e-7);
    EXPECT_NEAR(seen.y(), 0.2, 1e-7);
    EXPECT_EQ(seen.z(), 0.0);
    settings.ambient = Vector3(0.0, 0.0, 0.6);
    seen = centre_pixel(scene, settings);
    EXPECT_NEAR(seen.y(), 0.2, 1e-7);
    EXPECT_NEAR(seen.z(), 0.3, 1e-7);

    Camera beside = scene.camera();
    beside.look_at = Point3(5, 0, 0);
    scene.set_camera(beside);
    scene.commit();
    settings.background = Vector3(0.5, 0.0, 0.0);
    seen = centre_pixel(scene, settings);
    EXPECT_NEAR(seen.x(), 0.6, 1e-7);
    EXPECT_NEAR(seen.y(), 0.2, 1e-7);
    EXPECT_NEAR(seen.z(), 0.3, 1e-7);

    EXPECT_THROW(scene.set_ambient(Vector3(0, -1, 0)), InvalidParameter);
    EXPECT_THROW(scene.set_background(Vector3(0, kInfinity, 0)), InvalidParameter);
    EXPECT_EQ(scene.background(), Vector3(0.1, 0.2, 0.3));  // a refused value leaves it as it was
}

TEST(PointLight, FallsOffWithTheChosenPowerOfDistance) {
    // A white Lambert plane z = 0 facing a light on its normal at height h, seen head on:
    // radiance = albedo / pi * I / h^k. Two heights give the ratio (h2 / h1)^k.
    auto seen_at = [](double height, double falloff) {
        Scene scene;
        const auto white = scene.add_material(Material{"white", Vector3::Constant(1.0)});
        scene.add_object(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 0, 1)), white);
        PointLight light{Point3(0, 0, height), Vector3::Constant(1.0)};
        light.falloff = falloff;
        scene.add_light(light);
        test::set_view(scene, Point3(0, 0, 1), Point3(0, 0, 0));
        scene.commit();
        return centre_pixel(scene, RenderSettings{}).x();
    };
    for (double falloff : {0.0, 1.0, 2.0}) {
        // Float pixels: 1e-6 relative.
        EXPECT_NEAR(seen_at(2.0, falloff), 1.0 / kPi / std::pow(2.0, falloff), 1e-6) << falloff;
        EXPECT_NEAR(seen_at(2.0, falloff) / seen_at(4.0, falloff), std::pow(2.0, falloff), 1e-5)
            << falloff;
    }
    try {
        load_scene_from_string(
            R"({"objects": [], "lights": [{"type": "point", "position": [0, 1, 0], "falloff": 7}]})",
            "light.json");
        ADD_FAILURE() << "no error";
    } catch (const std::exception& error) {
        EXPECT_NE(std::string(error.what()).find("light.json: /lights/0/falloff: expected"),
                  std::string::npos)
            << error.what();
    }
}

TEST(MaterialKeys, TheSceneFileReadsAndChecksThem) {
    const std::string head = R"({"objects": [], "materials": {"m": {"albedo": 0.2, )";
    const Scene scene = load_scene_from_string(
        head + R"("specular": [0.3, 0.2, 0.1], "shininess": 50, "mirror": 0.5, "ior": 1.5}}})",
        "keys.json");
    ASSERT_EQ(scene.materials().size(), 2u);
    const Material& m = scene.materials()[1];
    EXPECT_EQ(m.specular, Vector3(0.3, 0.2, 0.1));
    EXPECT_EQ(m.shininess, 50.0);
    EXPECT_EQ(m.mirror, Vector3::Constant(0.5));
    EXPECT_EQ(m.ior, 1.5);
    // Defaults: none of the secondary terms.
    // The scene is kept: a reference into a temporary's materials would dangle (ASan).
    const Scene plain_scene =
        load_scene_from_string(R"({"objects": [], "materials": {"p": {}}})", "p.json");
    const Material& plain = plain_scene.materials()[1];
    EXPECT_EQ(plain.mirror, Vector3::Zero());
    EXPECT_EQ(plain.ior, 0.0);
    // Each bad value is an error naming the file, the place and what was expected.
    const std::vector<std::pair<std::string, std::string>> bad = {
        {R"("mirror": 1.5})", "/materials/m/mirror: expected values in [0, 1]"},
        {R"("specular": [0, -1, 0]})", "/materials/m/specular: expected values in [0, 1]"},
        {R"("shininess": -2})", "/materials/m/shininess: expected a Phong exponent"},
        {R"("ior": 0.5})", "/materials/m/ior: expected 0 (opaque) or an index"},
        {R"("ior": "glass"})", "/materials/m/ior: expected a number"},
    };
    for (const auto& [tail, message] : bad) {
        try {
            load_scene_from_string(head + tail + "}}", "bad.json");
            ADD_FAILURE() << tail << ": no error";
        } catch (const std::exception& error) {
            EXPECT_NE(std::string(error.what()).find("bad.json: " + message), std::string::npos)
                << error.what();
        }
    }
}

TEST(CsgMaterials, EachOperandShowsItsOwnAndACutShowsTheSubtractedOne) {
    // The unit box (red) minus a ball at its corner (blue) and minus a thin slot (unpainted),
    // in an object whose material is green. Seen from above, orthographically, lit from the
    // eye: the box's top face is red, the bite's cut is blue, the slot's cut takes the
    // object's green (docs/rendering.md, "Materials in CSG").
    Scene scene;
    const auto red = scene.add_material(Material{"red", Vector3(1, 0, 0)});
    const auto blue = scene.add_material(Material{"blue", Vector3(0, 0, 1)});
    const auto green = scene.add_material(Material{"green", Vector3(0, 1, 0)});
    const auto box =
        std::make_shared<Painted>(std::make_shared<Box>(Point3(0, 0, 0), Point3(1, 1, 1)), red);
    const auto ball =
        std::make_shared<Painted>(std::make_shared<Sphere>(Point3(1, 1, 1), 0.5), blue);
    const auto slot = std::make_shared<Box>(Point3(0.1, 0.4, 0.5), Point3(0.2, 0.6, 2));
    scene.add_object(make_difference(box, {ball, slot}), green);
    test::set_orthographic_view(scene, Point3(0.5, 0.5, 5), Point3(0.5, 0.5, 0), 1.0);
    scene.commit();
    RenderSettings settings = test::settings_of_size(10, 10);
    const Image image = render(scene, settings).image;
    // Pixel (x, y) looks down at (0.05 + 0.1 x, 0.95 - 0.1 y).
    auto colour = [&](int x, int y) {
        const Pixel& pixel = image.at(x, y);
        return Vector3(pixel.red, pixel.green, pixel.blue);
    };
    EXPECT_EQ(colour(3, 7), Vector3(1, 0, 0));  // (0.35, 0.25): the top face, facing up
    const Vector3 cut = colour(9, 0);           // (0.95, 0.95): inside the bite
    EXPECT_EQ(cut.x(), 0.0);
    EXPECT_EQ(cut.y(), 0.0);
    EXPECT_GT(cut.z(), 0.5);
    EXPECT_EQ(colour(1, 5), Vector3(0, 1, 0));  // (0.15, 0.45): the slot's floor, at z = 0.5
}

TEST(CsgMaterials, TheSceneFileGivesOperandsTheirMaterials) {
    // The docs' stone box with a gold-lined bite, plus a definition carrying its own material
    // inside a union whose other operand has none.
    const Scene scene = load_scene_from_string(R"({
      "materials": {"stone": {"albedo": 0.5}, "gold": {"albedo": [0.9, 0.7, 0.2]},
                    "blue": {"albedo": [0.1, 0.2, 0.9]}},
      "definitions": {"blue ball": {"type": "sphere", "radius": 0.5, "material": "blue"}},
      "objects": [
        {"type": "difference", "material": "stone", "operands": [
          {"type": "box", "lower": [-1, -1, -1], "upper": [1, 1, 1]},
          {"type": "sphere", "center": [1, 1, 1], "radius": 1, "material": "gold"}]},
        {"type": "union", "operands": [
          {"type": "ref", "definition": "blue ball", "transform": [{"translate": [4, 0, 0]}]},
          {"type": "sphere", "center": [5, 0, 0], "radius": 0.5}]}]})",
                                               "csg_materials.json");
    Scene committed = scene;
    committed.commit();
    QueryScratch scratch;
    auto material_seen = [&](double x, double y) {
        Ray ray;
        ray.origin = Point3(x, y, 10);
        ray.direction = Vector3(0, 0, -1);
        const std::optional<Hit> hit = committed.intersect(ray, scratch);
        EXPECT_TRUE(hit) << x << ", " << y;
        if (!hit || hit->material == kNoIndex) return std::string("object's");
        return committed.materials()[hit->material].name;
    };
    EXPECT_EQ(material_seen(-0.5, -0.5), "object's");  // the box's top: the object's stone
    EXPECT_EQ(committed.materials()[committed.objects()[0].material].name, "stone");
    EXPECT_EQ(material_seen(0.8, 0.8), "gold");  // the bite
    EXPECT_EQ(material_seen(4.0, 0.0), "blue");  // the definition's own
    EXPECT_EQ(material_seen(5.3, 0.0), "object's");
    EXPECT_EQ(committed.objects()[0].shape->children()[1]->kind(), "painted");
}

}  // namespace
}  // namespace csgrt
