// The scene format's half-space, complement, grid copy transforms, material ramps and arrays
// (docs/scene-format.md), judged against transforms built here, closed forms and the materials
// the file names.

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "csgrt/core/instance.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene_file.h"

namespace csgrt {
namespace {

Scene load(const std::string& text) { return load_scene_from_string(text, "test.json"); }

/// The world_from_object of a top-level object: the identity for a bare shape.
Transform placement_of(const SceneObject& object) {
    const auto* instance = dynamic_cast<const Instance*>(object.shape.get());
    return instance != nullptr ? instance->world_from_object() : Transform();
}

void expect_same_map(const Transform& actual, const Transform& expected, double tolerance) {
    for (const Point3& p : {Point3(0, 0, 0), Point3(1, 0, 0), Point3(0, 1, 0), Point3(0, 0, 1)}) {
        EXPECT_LE((actual.apply_point(p) - expected.apply_point(p)).norm(), tolerance)
            << p.transpose();
    }
}

TEST(SceneFileCopies, AHalfSpaceAndANotCutSolidsAsTheirClosedFormsSay) {
    Scene scene = load(R"({"objects": [
        {"type": "intersection", "operands": [{"type": "sphere", "radius": 2},
            {"type": "half_space", "point": [0, 0.5, 0], "normal": [0, 1, 0]}]},
        {"type": "intersection", "operands": [
            {"type": "box", "lower": [10, -1, -1], "upper": [12, 1, 1]},
            {"type": "not", "operand": {"type": "sphere", "center": [12, 0, 0], "radius": 1}}]}
    ]})");
    scene.commit();
    QueryScratch scratch;
    // Down onto the cut at y = 0.5 inside the disk of radius sqrt(3.75): the flat top.
    const auto top = scene.intersect(Ray{Point3(0.3, 5, 0.2), Vector3(0, -1, 0)}, scratch);
    ASSERT_TRUE(top);
    EXPECT_EQ(top->t, 4.5);
    EXPECT_EQ(top->geometric_normal, Normal3(0, 1, 0));
    // Up from below: the sphere's lower surface at y = -sqrt(4 - 0.09 - 0.04).
    const auto bottom = scene.intersect(Ray{Point3(0.3, -5, 0.2), Vector3(0, 1, 0)}, scratch);
    ASSERT_TRUE(bottom);
    EXPECT_NEAR(bottom->t, 5 - std::sqrt(4 - 0.09 - 0.04), 1e-14);
    // Along x through the box minus the ball at x = 12: the box face at x = 10, and from
    // inside the box at x = 10.5 the ball's surface at x = 11 with its normal flipped.
    const auto face = scene.intersect(Ray{Point3(8, 0, 0), Vector3(1, 0, 0)}, scratch);
    ASSERT_TRUE(face);
    EXPECT_EQ(face->t, 2.0);
    const auto hollow = scene.intersect(Ray{Point3(10.5, 0, 0), Vector3(1, 0, 0)}, scratch);
    ASSERT_TRUE(hollow);
    EXPECT_EQ(hollow->t, 0.5);
    EXPECT_EQ(hollow->geometric_normal, Normal3(1, 0, 0));  // out of the box-minus-ball
}

TEST(SceneFileCopies, GridCopyNIsTurnedNTimesByTheCopyTransform) {
    const Scene scene = load(R"({"objects": [{"type": "grid", "count": [4, 2, 1],
        "spacing": [3, 5, 0], "copy_transform": [{"rotate": {"axis": [0, 1, 0], "degrees": 30}},
        {"scale": 1.25}], "transform": [{"translate": [0, 0, 7]}],
        "item": {"type": "box", "lower": [-1, -0.5, -0.25], "upper": [1, 0.5, 0.25]}}]})");
    ASSERT_EQ(scene.objects().size(), 8u);
    const Transform step = Transform::scale(1.25) * Transform::rotate(Vector3(0, 1, 0), kPi / 6);
    Transform turned;
    for (std::size_t n = 0; n < 8; ++n) {
        // x fastest: cell (n % 4, n / 4), centred on the origin.
        const Vector3 offset(3.0 * (static_cast<double>(n % 4) - 1.5),
                             5.0 * (static_cast<double>(n / 4) - 0.5), 0.0);
        const Transform expected =
            Transform::translate(Vector3(0, 0, 7)) * Transform::translate(offset) * turned;
        SCOPED_TRACE(n);
        expect_same_map(placement_of(scene.objects()[n]), expected, 1e-13);
        turned = step * turned;
    }
}

TEST(SceneFileCopies, AMaterialRampBlendsAcrossTheCopies) {
    const Scene scene = load(R"({"materials": {
        "red": {"albedo": [1, 0, 0], "shininess": 10},
        "green": {"albedo": [0, 1, 0], "shininess": 20},
        "blue": {"albedo": [0, 0, 1], "shininess": 40}},
      "objects": [{"type": "grid", "count": [5, 1, 1], "spacing": [3, 0, 0],
        "material_ramp": ["red", "green", "blue"], "item": {"type": "sphere", "radius": 1}}]})");
    ASSERT_EQ(scene.objects().size(), 5u);
    // Copy c sits at c / 4 along red -> green -> blue: 0, 1/2, 1 (green), 3/2, 2 (blue).
    const Vector3 expected[5] = {{1, 0, 0}, {0.5, 0.5, 0}, {0, 1, 0}, {0, 0.5, 0.5}, {0, 0, 1}};
    const double shininess[5] = {10, 15, 20, 30, 40};
    for (std::size_t c = 0; c < 5; ++c) {
        const Material& material = scene.materials()[scene.objects()[c].material];
        EXPECT_EQ(material.albedo, expected[c]) << c;
        EXPECT_EQ(material.shininess, shininess[c]) << c;
        EXPECT_EQ(material.name, "red..blue[" + std::to_string(c) + "]");
    }
}

TEST(SceneFileCopies, ArrayCopiesTakeTheirOwnTransformsAndMaterials) {
    const Scene scene = load(R"({"materials": {"a": {"albedo": 0.2}, "b": {"albedo": 0.4}},
      "objects": [{"type": "array", "material": "a", "name": "row",
        "transform": [{"translate": [0, 10, 0]}],
        "item": {"type": "sphere", "radius": 1},
        "copies": [{}, {"transform": [{"scale": 2}, {"translate": [5, 0, 0]}], "material": "b"},
                   {"transform": [{"rotate": {"axis": [0, 0, 1], "degrees": 90}}]}]},
        {"type": "union", "operands": [{"type": "box", "lower": [-1, -1, -1], "upper": [1, 1, 1]},
          {"type": "array", "item": {"type": "sphere", "radius": 1},
           "copies": [{"transform": [{"translate": [2, 0, 0]}]},
                      {"transform": [{"translate": [-2, 0, 0]}]}]}]}]})");
    ASSERT_EQ(scene.objects().size(), 4u);
    const Transform up = Transform::translate(Vector3(0, 10, 0));
    expect_same_map(placement_of(scene.objects()[0]), up, 0.0);
    expect_same_map(placement_of(scene.objects()[1]),
                    up * Transform::translate(Vector3(5, 0, 0)) * Transform::scale(2.0), 1e-14);
    expect_same_map(placement_of(scene.objects()[2]),
                    up * Transform::rotate(Vector3(0, 0, 1), kPi / 2), 1e-15);
    const auto material_name = [&](std::size_t i) {
        return scene.materials()[scene.objects()[i].material].name;
    };
    EXPECT_EQ(material_name(0), "a");
    EXPECT_EQ(material_name(1), "b");
    EXPECT_EQ(material_name(2), "a");
    EXPECT_EQ(scene.objects()[1].name, "row[1]");
    // In a list an array stands for its copies: the union has three operands, three leaves.
    EXPECT_EQ(scene.objects()[3].shape->kind(), "union");
    const SceneShapeCounts counts = count_scene_shapes(scene);
    EXPECT_EQ(counts.by_kind.at("sphere"), 5u);
    EXPECT_EQ(counts.by_kind.at("box"), 1u);
}

TEST(SceneFileCopies, AGridOrArrayInsideAShapePaintsEachCopyWithItsMaterial) {
    // A box (the object's material "stone") minus a row of three balls centred on its top
    // face, their materials cycling a, b; a union with an array whose second copy names its
    // own; a nested grid under a ramp; a top-level grid over a nested grid naming none.
    Scene scene = load(R"({"materials": {"stone": {"albedo": 0.5}, "a": {"albedo": 0.2},
        "b": {"albedo": 0.4}, "cold": {"albedo": [0, 0, 1]}, "hot": {"albedo": [1, 0, 0]}},
      "objects": [
        {"type": "difference", "material": "stone", "operands": [
          {"type": "box", "lower": [-6, -1, -1], "upper": [6, 1, 1]},
          {"type": "grid", "count": [3, 1, 1], "spacing": [4, 0, 0], "materials": ["a", "b"],
           "transform": [{"translate": [0, 1, 0]}],
           "item": {"type": "sphere", "radius": 0.5}}]},
        {"type": "union", "operands": [{"type": "box", "lower": [-1, 9, -1], "upper": [1, 11, 1]},
          {"type": "array", "material": "a", "item": {"type": "sphere", "radius": 1},
           "copies": [{"transform": [{"translate": [3, 10, 0]}]},
                      {"transform": [{"translate": [-3, 10, 0]}], "material": "b"}]}]},
        {"type": "compound", "children": [
          {"type": "grid", "count": [3, 1, 1], "spacing": [4, 0, 0],
           "material_ramp": ["cold", "hot"], "transform": [{"translate": [0, 20, 0]}],
           "item": {"type": "sphere", "radius": 1}}]},
        {"type": "grid", "count": [2, 1, 1], "spacing": [4, 0, 0], "material": "b",
         "transform": [{"translate": [0, 30, 0]}],
         "item": {"type": "compound", "children": [
           {"type": "grid", "count": [1, 1, 1], "spacing": [0, 0, 0],
            "item": {"type": "sphere", "radius": 1}}]}}]})");
    scene.commit();
    QueryScratch scratch;
    const auto material_of = [&](const Ray& ray) -> std::string {
        const auto hit = scene.intersect(ray, scratch);
        if (!hit) return "miss";
        const std::uint32_t index =
            hit->material != kNoIndex ? hit->material : scene.objects()[hit->object_id].material;
        return scene.materials()[index].name;
    };
    const auto material_at = [&](double x, double y) {
        return material_of(Ray{Point3(x, y, 10), Vector3(0, 0, -1)});
    };
    // Object 0, from above: at x = -4, 0, 4 the top face is inside a ball, so the ray meets
    // the ball's lower half at y = 0.5, the cut, which shows the subtracted ball's material;
    // between the balls, the box's own face.
    const auto from_above = [&](double x) {
        return material_of(Ray{Point3(x, 5, 0), Vector3(0, -1, 0)});
    };
    EXPECT_EQ(from_above(-4.0), "a");
    EXPECT_EQ(from_above(0.0), "b");
    EXPECT_EQ(from_above(4.0), "a");
    EXPECT_EQ(from_above(2.0), "stone");
    EXPECT_EQ(scene.intersect(Ray{Point3(0, 5, 0), Vector3(0, -1, 0)}, scratch)->t, 4.5);
    // Object 1: the box takes the object's default; the copies a and, on its own, b.
    EXPECT_EQ(material_at(0.0, 10.0), "default");
    EXPECT_EQ(material_at(3.0, 10.0), "a");
    EXPECT_EQ(material_at(-3.0, 10.0), "b");
    // Object 2: the ramp's blends, one new material per copy, as at the top level.
    EXPECT_EQ(material_at(-4.0, 20.0), "cold..hot[0]");
    EXPECT_EQ(material_at(0.0, 20.0), "cold..hot[1]");
    EXPECT_EQ(material_at(4.0, 20.0), "cold..hot[2]");
    EXPECT_EQ(scene.materials()[7].albedo, Vector3(0.5, 0, 0.5));
    // Objects 3 and 4: a top-level grid's material is the objects'; the grid nested in its
    // item named none, so its copy is not painted and the object's shows.
    EXPECT_EQ(material_at(-2.0, 30.0), "b");
    EXPECT_EQ(scene.objects()[3].material, scene.objects()[4].material);
    EXPECT_EQ(count_scene_shapes(scene).by_kind.at("painted"), 3u + 2u + 3u);
}

TEST(SceneFileCopies, TenThousandObjectsEachTurnedAndColouredFromASmallFile) {
    const std::string text = R"({"materials": {"cold": {"albedo": [0.1, 0.2, 0.9]},
        "hot": {"albedo": [0.9, 0.2, 0.1]}},
      "objects": [{"type": "grid", "count": [100, 1, 100], "spacing": [2, 0, 2],
        "copy_transform": [{"rotate": {"axis": [0, 1, 0], "degrees": 0.0359}}],
        "material_ramp": ["cold", "hot"],
        "item": {"type": "box", "lower": [-0.5, -0.1, -0.2], "upper": [0.5, 0.1, 0.2]}}]})";
    EXPECT_LT(text.size(), 500u);
    const Scene scene = load(text);
    ASSERT_EQ(scene.objects().size(), 10'000u);
    std::set<double> reds, angles;
    for (const SceneObject& object : scene.objects()) {
        reds.insert(scene.materials()[object.material].albedo.x());
        const Vector3 x_axis = placement_of(object).apply_vector(Vector3(1, 0, 0));
        angles.insert(std::atan2(-x_axis.z(), x_axis.x()));
    }
    EXPECT_EQ(reds.size(), 10'000u);
    EXPECT_EQ(angles.size(), 10'000u);
    // The last copy turned 9,999 times by 0.0359 degrees: 358.96 degrees.
    const Vector3 last = placement_of(scene.objects().back()).apply_vector(Vector3(1, 0, 0));
    EXPECT_NEAR(std::atan2(-last.z(), last.x()), (9999 * 0.0359 - 360) * kPi / 180, 1e-9);
}

}  // namespace
}  // namespace csgrt
