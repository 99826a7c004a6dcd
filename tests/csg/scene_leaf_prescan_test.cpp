#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene_file.h"
#include "support/scene_error.h"

namespace csgrt {
namespace {

/// A grid of 10^3 copies of a legal grid of 10^6 spheres (10^9 leaves).
const std::string kNestedGrids =
    R"({"type": "grid", "count": [10, 10, 10], "spacing": [3, 3, 3], "item": {"type": "grid",)"
    R"( "count": [100, 100, 100], "spacing": [0.01, 0.01, 0.01], "item": {"type": "sphere",)"
    R"( "radius": 0.004}}})";

TEST(SceneLeafPrescan, NestedGridsAreRefusedAtTheOuterCountWithTheProduct) {
    const std::string message = test::scene_error_of(R"({"objects": [)" + kNestedGrids + "]}");
    EXPECT_NE(message.find("test.json: /objects/0/count: 1000 copies of an item of 1000000 leaf "
                           "shapes are more than the 10000000 leaves"),
              std::string::npos)
        << message;
}

TEST(SceneLeafPrescan, TheCountComesBeforeAnythingIsBuilt) {
    // Object 0 is broken (its sphere would fail when built); object 1 is over the cap. The cap
    // is reported first: the count ran on the parsed JSON before object 0 was built, so the
    // inner 10^6-sphere grid of object 1 was never built either.
    const std::string message =
        test::scene_error_of(R"({"objects": [{"type": "sphere", "radius": -1}, )" + kNestedGrids + "]}");
    EXPECT_NE(message.find("test.json: /objects/1/count: 1000 copies"), std::string::npos)
        << message;
}

TEST(SceneLeafPrescan, GridsInsideDefinitionsAndListsAreCountedPerUse) {
    // d is a grid of 10^6 spheres (legal); eleven uses in a union pass 10^7.
    std::string text =
        R"({"definitions": {"d": {"type": "grid", "count": [100, 100, 100], "spacing": [1, 1, 1],)"
        R"( "item": {"type": "sphere", "radius": 0.1}}}, "objects": [{"type": "union",)"
        R"( "operands": [)";
    for (int i = 0; i < 11; ++i)
        text += std::string(i ? ", " : "") + R"({"type": "ref", "definition": "d"})";
    text += "]}]}";
    const std::string message = test::scene_error_of(text);
    EXPECT_NE(message.find("test.json: /objects/0: the scene expands to 11000000 leaf shapes"),
              std::string::npos)
        << message;
}

TEST(ShapeChildren, CompositesListTheirPartsInOrderAndLeavesNone) {
    const auto a = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    const auto b = std::make_shared<Sphere>(Point3(1, 0, 0), 1.0);
    EXPECT_TRUE(a->children().empty());
    const Instance instance(a, Transform::translate(Vector3(1, 2, 3)));
    ASSERT_EQ(instance.children().size(), 1u);
    EXPECT_EQ(instance.children()[0], a.get());
    const auto difference = make_difference(a, {b});
    const auto operands = difference->children();
    ASSERT_EQ(operands.size(), 2u);
    EXPECT_EQ(operands[0], a.get());
    EXPECT_EQ(operands[1], b.get());
    const Compound compound({b, a, b});
    const auto children = compound.children();
    ASSERT_EQ(children.size(), 3u);
    EXPECT_EQ(children[0], b.get());
    EXPECT_EQ(children[1], a.get());
    EXPECT_EQ(children[2], b.get());
}

TEST(InvalidParameterName, RequireNamesTheParameterAndPlainErrorsNone) {
    try {
        Sphere(Point3(0, 0, 0), -1.0);
        FAIL() << "a negative radius was accepted";
    } catch (const InvalidParameter& error) {
        EXPECT_EQ(error.parameter(), "radius") << error.what();
    }
    EXPECT_EQ(InvalidParameter("no single parameter").parameter(), "");
}

}  // namespace
}  // namespace csgrt
