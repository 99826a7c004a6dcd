// Hostile scene files that describe more work than they look (issue 15): chains of refs,
// coincident and nearly coincident copies, piles at the top level. Each case is judged by
// what the loaded scene does (hits where geometry puts them, work a counted query reports),
// not by a time.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene_file.h"
#include "support/scene_error.h"
#include "support/scene_texts.h"
#include "support/test_scale.h"

namespace csgrt {
namespace {

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
    Scene scene = load_scene_from_string(test::doubling_scene(20, 0.0), "test.json");
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
    EXPECT_EQ(test::scene_error_of(test::doubling_scene(13, 1e-9)), "no error");
    const std::string message = test::scene_error_of(test::doubling_scene(20, 1e-9));
    EXPECT_NE(message.find("test.json: /definitions/d14: about 16384 leaf shapes overlap at one "
                           "point"),
              std::string::npos)
        << message;
    // Moved by more than their size, the copies are no pile: 2^20 spheres side by side.
    EXPECT_EQ(test::scene_error_of(test::doubling_scene(20, 2.5, true)), "no error");
    // But equal moves at every level pile C(k, j) copies at j * 2.5, C(16, 8) = 12870 at d16
    // (the estimate, which adds up overlapping children, says 2^14 there).
    EXPECT_NE(test::scene_error_of(test::doubling_scene(20, 2.5))
                  .find("/definitions/d16: about 16384 leaf shapes"),
              std::string::npos);
}

TEST(SceneFileLimits, AGridPiledCloserThanItsItemIsRefusedAtItsCount) {
    const auto grid = [](const std::string& spacing) {
        std::string text = R"({"objects": [{"type": "grid", "count": [30, 30, 30], "spacing": [)";
        text.append(spacing).append(", ").append(spacing).append(", ").append(spacing);
        return text.append(R"(], "item": {"type": "sphere", "radius": 1}}]})");
    };
    // Boxes 2 wide, 0.1 apart: floor(2 / 0.1) + 1 = 21 copies meet along each axis, 9261.
    EXPECT_EQ(test::scene_error_of(grid("0.1")), "no error");
    // 0.095 apart: 22 along each axis, 10648.
    const std::string message = test::scene_error_of(grid("0.095"));
    EXPECT_NE(message.find("test.json: /objects/0/count: 10648 copies meet at one point"),
              std::string::npos)
        << message;
    // Spacing 0 makes exact repeats, which cost one test.
    EXPECT_EQ(test::scene_error_of(grid("0")), "no error");
    // An item that can never be hit (its box is empty) piles up nothing.
    EXPECT_EQ(test::scene_error_of(R"({"objects": [{"type": "grid", "count": [30, 30, 30], "spacing": )"
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
    const std::string message = test::scene_error_of(spheres(10'001, 1e-9, false));
    EXPECT_NE(message.find("with the objects around it, about 10001 leaf shapes overlap"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("test.json: /objects/"), std::string::npos) << message;
    EXPECT_EQ(test::scene_error_of(spheres(12'000, 0.0, true)), "no error");
}

TEST(SceneFileLimits, APileWrittenOutAmongManyObjectsIsFoundWhereverItIs) {
    // 20,000 spheres side by side along x, and interleaved with them, never at an index that
    // is a multiple of 468 (the stride of the 64 samples the estimate took before), 10,001
    // spheres a nanometre apart at x = -100: every member's centre is a sample now, so the
    // pile is found, at its first sphere (object 1).
    constexpr int kSpread = 20'000, kPile = 10'001;
    constexpr int kStride = (kSpread + kPile) / 64;
    std::string text = R"({"objects": [)";
    int spread = 0, piled = 0;
    for (int i = 0; i < kSpread + kPile; ++i) {
        const bool pile = i % kStride != 0 && piled < kPile;
        char object[160];
        std::snprintf(object, sizeof object,
                      R"(%s{"type": "sphere", "center": [%.17g, 0, 0], "radius": 1})",
                      i ? ", " : "", pile ? -100.0 + 1e-9 * piled++ : 3.0 * spread++);
        text += object;
    }
    text += "]}";
    const std::string message = test::scene_error_of(text);
    EXPECT_NE(message.find("test.json: /objects/1: with the objects around it, about 10001 leaf "
                           "shapes overlap"),
              std::string::npos)
        << message;
}

/// The box of sphere `centre`, `radius` as the test sees it.
struct SphereBox {
    Eigen::Vector3d lower, upper;
    bool contains(const Eigen::Vector3d& p) const {
        return (p.array() >= lower.array()).all() && (p.array() <= upper.array()).all();
    }
    bool encloses(const SphereBox& inner, double margin) const {
        return (lower.array() <= inner.lower.array() - margin).all() &&
               (upper.array() >= inner.upper.array() + margin).all();
    }
};

TEST(SceneFileLimits, TheOverlapOfALongListIsTheDirectCountAtEveryCentre) {
    // Members of 200 leaves each (a compound of 200 spheres a nanometre apart) scattered with
    // sizes from 0.3 to 6 in cubes of different sides: the estimate the loader reports (the
    // largest sum, at the first member where it is reached) against the count written out
    // here, every member tested at every member's centre, leaving out the ones that enclose
    // the sample's box or that it encloses by 1% of its diagonal (docs/scene-format.md,
    // Limits). The loader's tree takes or skips whole groups; the sums must be the same.
    constexpr int kLeaves = 200, kMembers = 600;
    std::string blob = R"({"definitions": {"blob": {"type": "compound", "children": [)";
    for (int k = 0; k < kLeaves; ++k) {
        char child[96];
        std::snprintf(child, sizeof child,
                      R"(%s{"type": "sphere", "center": [%.17g, 0, 0], "radius": 1})",
                      k ? ", " : "", 1e-9 * k);
        blob += child;
    }
    blob += "]}}, ";
    int refused = 0;
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
        std::mt19937_64 random(seed);
        const double side = 4.0 + 1.0 * static_cast<double>(seed);
        std::uniform_real_distribution<double> position(0.0, side), log_size(-1.2, 1.8);
        std::string text = blob + R"("objects": [)";
        std::vector<SphereBox> boxes;
        for (int i = 0; i < kMembers; ++i) {
            const double scale = std::exp(log_size(random));
            const Eigen::Vector3d at(position(random), position(random), position(random));
            char object[256];
            std::snprintf(object, sizeof object,
                          R"(%s{"type": "ref", "definition": "blob", "transform": [)"
                          R"({"scale": %.17g}, {"translate": [%.17g, %.17g, %.17g]}]})",
                          i ? ", " : "", scale, at.x(), at.y(), at.z());
            text += object;
            const Eigen::Vector3d reach(1.0 + 1e-9 * (kLeaves - 1), 1.0, 1.0);
            boxes.push_back({at - Eigen::Vector3d::Constant(scale), at + scale * reach});
        }
        text += "]}";
        std::uint64_t worst = kLeaves;
        int worst_at = -1;
        for (int s = 0; s < kMembers; ++s) {
            const SphereBox& sample = boxes[s];
            const Eigen::Vector3d centre = 0.5 * (sample.lower + sample.upper);
            const double margin = 0.01 * (sample.upper - sample.lower).norm();
            std::uint64_t leaves = 0;
            for (const SphereBox& other : boxes) {
                if (other.contains(centre) && !other.encloses(sample, margin) &&
                    !sample.encloses(other, margin)) {
                    leaves += kLeaves;
                }
            }
            if (leaves > worst) {
                worst = leaves;
                worst_at = s;
            }
        }
        const std::string message = test::scene_error_of(text);
        if (worst <= 10'000) {
            EXPECT_EQ(message, "no error") << "seed " << seed << ", direct count " << worst;
            continue;
        }
        ++refused;
        const std::string expected = "test.json: /objects/" + std::to_string(worst_at) +
                                     ": with the objects around it, about " +
                                     std::to_string(worst) + " leaf shapes overlap";
        EXPECT_EQ(message.rfind(expected, 0), 0u) << "seed " << seed << ": " << message;
    }
    // Both answers occur among the seeds.
    EXPECT_GT(refused, 0);
    EXPECT_LT(refused, 12);
}

TEST(SceneFileLimits, AnErrorDeepDownNamesItsPlaceThroughEveryLevel) {
    // 255 unions nested (510 JSON levels), the innermost sphere's radius wrong: the pointer,
    // built from its steps only for the message, keeps its ends around the levels left out.
    std::string text = R"({"objects": [)";
    for (int i = 0; i < 255; ++i) text += R"({"type": "union", "operands": [)";
    text += R"({"type": "sphere", "radius": -1})";
    for (int i = 0; i < 255; ++i) text += R"(, {"type": "sphere", "radius": 1}]})";
    text += "]}";
    const std::string message = test::scene_error_of(text);
    EXPECT_EQ(message.rfind("test.json: /objects/0/operands/0/operands/0/", 0), 0u) << message;
    // "/objects/0", 255 steps "/operands/0" of 11 characters, "/radius": 2822 characters.
    // The first 120 end where step 11 starts, the last 120 begin inside step 245, so steps 11
    // to 244 are left out: 234 steps of two tokens.
    EXPECT_NE(message.find("/operands/0/...(468 levels).../operands/0/operands/0"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("/operands/0/operands/0/radius: Sphere: radius"), std::string::npos)
        << message;
}

TEST(SceneFileLimitsHeavy, MoreThanTwoToTheTwentyFiveJsonValuesAreRefusedWhereTheyPassIt) {
    // 256 MiB of "0," (2 bytes a value, under the file-size cap) built a tree of 4.6 GB; the
    // parser now stops at the value past 2^25. The root object and the array are values 1
    // and 2, so zero k is value k + 3 and zero 2^25 - 2 the first too many: the ones before
    // it, up to the limit exactly, were taken. (The limit is fixed, so the sanitizer build,
    // which runs the heavy tests smaller, skips this one.)
    if (test::reduced_scale()) GTEST_SKIP() << "the value limit does not scale";
    constexpr std::size_t kZeros = (std::size_t{1} << 25) + 8;
    std::string text = R"({"objects": [)";
    text.reserve(2 * kZeros + 16);
    for (std::size_t i = 0; i < kZeros; ++i) text.append(i ? ",0" : "0");
    text += "]}";
    const std::string message = test::scene_error_of(text);
    EXPECT_EQ(message, "test.json: /objects/33554430: more than 33554432 JSON values (numbers, "
                       "strings, arrays and objects; docs/scene-format.md, Limits)");
}

}  // namespace
}  // namespace csgrt
