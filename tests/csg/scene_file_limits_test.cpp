// Hostile scene files that describe more work than they look (issue 15): chains of refs,
// coincident and nearly coincident copies, piles at the top level. Each case is judged by
// what the loaded scene does (hits where geometry puts them, work a counted query reports),
// not by a time.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene_file.h"

namespace csgrt {
namespace {

std::string error_of(const std::string& text) {
    try {
        load_scene_from_string(text, "test.json");
    } catch (const SceneError& error) {
        return error.what();
    }
    return "no error";
}

/// d0 is a unit sphere; d_k = compound [d_{k-1}, d_{k-1} moved along x by `offset`, times
/// 2^(k-1) when `growing` (then no two copies share a place)].
std::string doubling(int levels, double offset, bool growing = false) {
    std::string text = R"({"definitions": {"d0": {"type": "sphere", "radius": 1})";
    for (int k = 1; k <= levels; ++k) {
        // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
        const std::string below = std::string("d").append(std::to_string(k - 1));
        text.append(", \"d").append(std::to_string(k));
        text.append(R"(": {"type": "compound", "children": [{"type": "ref", "definition": ")");
        text.append(below).append(R"("}, {"type": "ref", "definition": ")").append(below);
        char moved[32];
        std::snprintf(moved, sizeof moved, "%.17g", growing ? std::ldexp(offset, k - 1) : offset);
        text.append(R"(", "transform": [{"translate": [)").append(moved).append(", 0, 0]}]}]}");
    }
    return text.append(R"(}, "objects": [{"type": "ref", "definition": "d)")
        .append(std::to_string(levels))
        .append("\"}]}");
}

TEST(SceneFileLimits, ALegalChainOfTwentyThousandRefsLoadsWhereItPutsTheSphere) {
    // d_k = d_{k-1} moved by 1/1024 (exact in binary, so the folded sum is exact): 20,000
    // refs, each found by its name in constant time (a linear search of the definitions took
    // 17 s for 10^5 of them, docs/accuracy.md; 0.7 s for these).
    std::string text = R"({"definitions": {"d0": {"type": "sphere", "radius": 1})";
    for (int k = 1; k <= 20'000; ++k) {
        text.append(", \"d").append(std::to_string(k)).append(R"(": {"type": "ref", )");
        text.append(R"("definition": "d)").append(std::to_string(k - 1));
        text.append(R"(", "transform": [{"translate": [0.0009765625, 0, 0]}]})");
    }
    text.append(R"(}, "objects": [{"type": "ref", "definition": "d20000"}]})");
    Scene scene = load_scene_from_string(text, "test.json");
    scene.commit();
    // The sphere's centre is at x = 20000 / 1024 = 19.53125.
    QueryScratch scratch;
    const auto hit = scene.intersect(Ray{Point3(19.53125, 0, -10), Vector3(0, 0, 1)}, scratch);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->t, 9.0);
    EXPECT_FALSE(scene.intersect(Ray{Point3(18.5, 0, -10), Vector3(0, 0, 1)}, scratch));
}

TEST(SceneFileLimits, ExactlyCoincidentCopiesCostOneTest) {
    // 2^20 copies of one sphere in one place (the transform a zero translation).
    Scene scene = load_scene_from_string(doubling(20, 0.0), "test.json");
    const auto& top = dynamic_cast<const Compound&>(*scene.objects().front().shape);
    // Each compound keeps one of its two equal children.
    EXPECT_EQ(top.accelerator_stats().primitives, 1u);
    scene.commit();
    QueryScratch scratch;
    const auto hit = scene.intersect(Ray{Point3(0.5, 0, -10), Vector3(0, 0, 1)}, scratch);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->t, 10.0 - std::sqrt(0.75), 1e-14);
}

TEST(SceneFileLimits, APileOfNearlyCoincidentCopiesIsRefusedAtItsDefinition) {
    // 2^13 copies a nanometre apart load; d14 has 2^14 > 10,000 and is named.
    EXPECT_EQ(error_of(doubling(13, 1e-9)), "no error");
    const std::string message = error_of(doubling(20, 1e-9));
    EXPECT_NE(message.find("test.json: /definitions/d14: about 16384 leaf shapes overlap at one "
                           "point"),
              std::string::npos)
        << message;
    // Moved by more than their size, the copies are no pile: 2^20 spheres side by side.
    EXPECT_EQ(error_of(doubling(20, 2.5, true)), "no error");
    // But equal moves at every level pile C(k, j) copies at j * 2.5, C(16, 8) = 12870 at d16
    // (the estimate, which adds up overlapping children, says 2^14 there).
    EXPECT_NE(error_of(doubling(20, 2.5)).find("/definitions/d16: about 16384 leaf shapes"),
              std::string::npos);
}

TEST(SceneFileLimits, AGridPiledCloserThanItsItemIsRefusedAtItsCount) {
    const auto grid = [](const std::string& spacing) {
        std::string text = R"({"objects": [{"type": "grid", "count": [30, 30, 30], "spacing": [)";
        text.append(spacing).append(", ").append(spacing).append(", ").append(spacing);
        return text.append(R"(], "item": {"type": "sphere", "radius": 1}}]})");
    };
    // Boxes 2 wide, 0.1 apart: floor(2 / 0.1) + 1 = 21 copies meet along each axis, 9261.
    EXPECT_EQ(error_of(grid("0.1")), "no error");
    // 0.095 apart: 22 along each axis, 10648.
    const std::string message = error_of(grid("0.095"));
    EXPECT_NE(message.find("test.json: /objects/0/count: 10648 copies meet at one point"),
              std::string::npos)
        << message;
    // Spacing 0 makes exact repeats, which cost one test.
    EXPECT_EQ(error_of(grid("0")), "no error");
    // An item that can never be hit (its box is empty) piles up nothing.
    EXPECT_EQ(error_of(R"({"objects": [{"type": "grid", "count": [30, 30, 30], "spacing": )"
                       R"([1e-9, 1e-9, 1e-9], "item": {"type": "intersection", "operands": [)"
                       R"({"type": "sphere", "radius": 1}, {"type": "sphere", "center": )"
                       R"([5, 0, 0], "radius": 1}]}}]})"),
              "no error");
}

/// `count` unit spheres as top-level objects: centres `step` apart along x, or, when
/// `nested`, concentric with radii 1, 2, ..., count.
std::string spheres(int count, double step, bool nested) {
    std::string text = R"({"objects": [)";
    for (int i = 0; i < count; ++i) {
        char object[160];
        std::snprintf(object, sizeof object,
                      R"(%s{"type": "sphere", "center": [%.17g, 0, 0], "radius": %d})",
                      i ? ", " : "", nested ? 0.0 : i * step, nested ? i + 1 : 1);
        text += object;
    }
    return text + "]}";
}

TEST(SceneFileLimits, TheOverlapEstimateTracksTheWorkOfARay) {
    // What the estimate claims, checked on the scene's structure: 9,000 spheres a nanometre
    // apart cost a ray thousands of tests, 9,000 concentric shells a handful.
    const Ray into_the_pile{Point3(0, 0.25, -20), Vector3(0, 0, 1)};
    QueryScratch scratch;
    Scene pile = load_scene_from_string(spheres(9'000, 1e-9, false), "test.json");
    pile.commit();
    TraversalCounters pile_work;
    ASSERT_TRUE(pile.intersect_counted(into_the_pile, scratch, pile_work).has_value());
    EXPECT_GT(pile_work.primitives_tested, 4'000u);
    Scene onion = load_scene_from_string(spheres(9'000, 0.0, true), "test.json");
    onion.commit();
    TraversalCounters onion_work;
    const Ray into_the_onion{Point3(0, 0.25, -20'000), Vector3(0, 0, 1)};
    ASSERT_TRUE(onion.intersect_counted(into_the_onion, scratch, onion_work).has_value());
    EXPECT_LT(onion_work.primitives_tested, 64u);
    // 10,001 in a pile are refused, naming an object; the shells are not a pile.
    const std::string message = error_of(spheres(10'001, 1e-9, false));
    EXPECT_NE(message.find("with the objects around it, about 10001 leaf shapes overlap"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("test.json: /objects/"), std::string::npos) << message;
    EXPECT_EQ(error_of(spheres(12'000, 0.0, true)), "no error");
}

}  // namespace
}  // namespace csgrt
