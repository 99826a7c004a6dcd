#include "csgrt/csg/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <thread>

#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/plane.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "support/random.h"
#include "support/scene_parts.h"
#include "support/test_output.h"

namespace csgrt {
namespace {

// The example of docs/scene.md, verbatim between the markers: a 20-object scene in C++.
Scene docs_example() {
    // docs-example-begin
    using namespace csgrt;
    Scene scene;
    const std::uint32_t red = scene.add_material(Material{"red", {0.8, 0.2, 0.2}});
    auto ball = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    auto bite = std::make_shared<Sphere>(Point3(0.6, 0.6, 0.6), 0.7);
    auto bitten = std::make_shared<Boolean>(BooleanOperation::Difference, ball, bite);
    for (int i = 0; i < 20; ++i) {  // a ring of 20 instances of one bitten ball
        const double angle = kTwoPi * i / 20;
        const Transform placement =
            Transform::translate({6 * std::sin(angle), 1, 6 * std::cos(angle)}) *
            Transform::rotate({0, 1, 0}, angle);
        scene.add_object(std::make_shared<Instance>(bitten, placement), i % 2 ? red : 0,
                         "ball " + std::to_string(i));
    }
    scene.add_light(PointLight{{0, 10, 10}, {200, 200, 200}});
    Camera camera;
    camera.position = {0, 8, 14};
    scene.set_camera(camera);
    scene.commit();        // bounds and the hierarchy over the 20 objects
    QueryScratch scratch;  // one per thread
    if (auto hit = scene.intersect(scene.camera().generate_ray(0.5, 0.5, 1.5), scratch))
        std::printf("object %u (%s) at t = %g\n", hit->object_id,
                    scene.objects()[hit->object_id].name.c_str(), hit->t);
    // docs-example-end
    return scene;
}

TEST(Scene, DocsExampleBuildsAndHitsTheNearestBall) {
    const Scene scene = docs_example();
    ASSERT_TRUE(scene.is_committed());
    EXPECT_EQ(scene.objects().size(), 20u);
    EXPECT_EQ(scene.materials().size(), 2u);
    EXPECT_EQ(scene.materials()[0].name, "default");
    const auto names = accelerator_names();
    const bool has_bvh = std::find(names.begin(), names.end(), "bvh") != names.end();
    EXPECT_EQ(scene.accelerator_name(), has_bvh ? "bvh" : "brute");
    EXPECT_FALSE(scene.accelerator_reason().empty());
    // Ball 0 sits at (0, 1, 6), on the line from (0, 1, 20): the nearest of the ring.
    QueryScratch scratch;
    const auto hit = scene.intersect(Ray{Point3(0, 1, 20), Vector3(0, 0, -1)}, scratch);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->object_id, 0u);
    EXPECT_NEAR(hit->t, 13.0, 1e-12);
    EXPECT_TRUE(scene.bounds().contains(Point3(6, 1, 0)));
    EXPECT_NEAR(scene.bounds().upper.y(), 2.0, 1e-12);
}

TEST(Scene, DocsShowTheExampleVerbatim) {
    const std::filesystem::path root(CSGRT_SOURCE_DIR);
    const std::string source = test::file_contents(root / "tests" / "csg" / "scene_test.cpp");
    const std::string begin_marker = "// docs-example-begin\n";
    const auto begin = source.find(begin_marker) + begin_marker.size();
    const auto end = source.rfind("\n", source.find("    // docs-example-end")) + 1;
    // The example without its four spaces of indentation.
    std::istringstream lines(source.substr(begin, end - begin));
    std::string example, line;
    while (std::getline(lines, line)) example += (line.size() >= 4 ? line.substr(4) : line) + "\n";
    ASSERT_GT(example.size(), 500u);
    EXPECT_NE(test::file_contents(root / "docs" / "scene.md").find("```cpp\n" + example + "```"),
              std::string::npos)
        << "docs/scene.md does not show the example of scene_test.cpp:\n"
        << example;
}

TEST(Scene, ObjectIdsNameTheObjectAndTiesGoToTheLowerIndex) {
    Scene scene;
    auto a = std::make_shared<Sphere>(Point3(0, 1, 0), 1.0);
    scene.add_object(std::make_shared<Sphere>(Point3(5, 1, 0), 1.0));  // 0
    scene.add_object(test::ground_plane());                            // 1
    scene.add_object(a);                                               // 2
    scene.add_object(a);                                               // 3: the same sphere
    scene.commit();
    QueryScratch scratch;
    auto hit = scene.intersect(Ray{Point3(0, 10, 0), Vector3(0, -1, 0)}, scratch);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->object_id, 2u);
    EXPECT_DOUBLE_EQ(hit->t, 8.0);
    hit = scene.intersect(Ray{Point3(5, 10, 0), Vector3(0, -1, 0)}, scratch);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->object_id, 0u);
    hit = scene.intersect(Ray{Point3(50, 10, 0), Vector3(0, -1, 0)}, scratch);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->object_id, 1u);
    EXPECT_EQ(hit->shape, scene.objects()[1].shape.get());
    // From below, the ground (1) and sphere 2 touch at the origin: t = 1 for both, 1 wins.
    hit = scene.intersect(Ray{Point3(0, -1, 0), Vector3(0, 1, 0)}, scratch);
    EXPECT_EQ(hit->object_id, 1u);
    EXPECT_DOUBLE_EQ(hit->t, 1.0);
    EXPECT_FALSE(scene.bounds().is_empty());
    EXPECT_TRUE(scene.bounds().is_finite());
    EXPECT_NE(scene.accelerator_reason().find("unbounded"), std::string::npos);
}

TEST(Scene, LifecycleAndValidation) {
    Scene scene;
    QueryScratch scratch;
    const Ray ray{Point3(0, 0, 10), Vector3(0, 0, -1)};
    EXPECT_FALSE(scene.intersect(ray, scratch));  // not committed
    scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0));
    EXPECT_FALSE(scene.intersect(ray, scratch));
    scene.commit();
    EXPECT_TRUE(scene.intersect(ray, scratch));
    EXPECT_TRUE(scene.occluded(ray, scratch));
    scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 5), 1.0));
    EXPECT_FALSE(scene.is_committed());
    EXPECT_FALSE(scene.intersect(ray, scratch));
    scene.commit(test::structure_named<SceneConfig>("brute"));
    EXPECT_EQ(scene.intersect(ray, scratch)->object_id, 1u);
    EXPECT_EQ(scene.accelerator_name(), "brute");

    EXPECT_THROW(scene.add_object(nullptr), InvalidParameter);
    EXPECT_THROW(scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0), 7),
                 InvalidParameter);
    EXPECT_THROW(scene.add_material(Material{"hot", {1.5, 0, 0}}), InvalidParameter);
    EXPECT_THROW(scene.commit(test::structure_named<SceneConfig>("octree")), InvalidParameter);
    EXPECT_FALSE(scene.is_committed());
    Camera camera;
    camera.look_at = camera.position;
    scene.set_camera(camera);
    EXPECT_THROW(scene.commit(), InvalidParameter);

    Scene empty;
    empty.commit();
    EXPECT_FALSE(empty.intersect(ray, scratch));
    EXPECT_FALSE(empty.occluded(ray, scratch));
    EXPECT_TRUE(empty.bounds().is_empty());
}

TEST(Scene, InvalidRaysHitNothing) {
    Scene scene;
    scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0));
    scene.add_object(test::ground_plane());
    scene.commit();
    QueryScratch scratch;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const Ray& ray :
         {Ray{Point3(nan, 0, 5), Vector3(0, 0, -1)},
          Ray{Point3(0, 0, 5), Vector3(0, -kInfinity, -1)}, Ray{Point3(0, 0, 5), Vector3(0, 0, 0)},
          Ray{Point3(0, 0, 5), Vector3(0, 0, -1), 2.0, 1.0}}) {
        EXPECT_FALSE(scene.intersect(ray, scratch));
        EXPECT_FALSE(scene.occluded(ray, scratch));
    }
}

struct RandomScene {
    Scene scene;
    Scene brute;
};

// 300 objects: spheres, bitten spheres (booleans), small compounds and a ground plane, in one
// scene committed with "auto" and one with brute force.
RandomScene random_scene(std::uint64_t seed) {
    test::Random random(seed);
    std::vector<std::shared_ptr<const Shape>> shapes;
    for (int i = 0; i < 300; ++i) {
        const Point3 c(random.uniform(-20, 20), random.uniform(0, 10), random.uniform(-20, 20));
        const double r = random.uniform(0.3, 1.5);
        auto ball = std::make_shared<Sphere>(c, r);
        switch (i % 3) {
            case 0:
                shapes.push_back(ball);
                break;
            case 1:
                shapes.push_back(std::make_shared<Boolean>(
                    BooleanOperation::Difference, ball,
                    std::make_shared<Sphere>(c + Vector3(r, r, 0) * 0.5, r * 0.6)));
                break;
            default:
                shapes.push_back(
                    std::make_shared<Compound>(std::vector<std::shared_ptr<const Shape>>{
                        ball, std::make_shared<Sphere>(c + Vector3(0, 2 * r, 0), 0.5 * r)}));
        }
        if (i == 150) shapes.push_back(test::ground_plane());
    }
    RandomScene result;
    for (const auto& shape : shapes) {
        result.scene.add_object(shape);
        result.brute.add_object(shape);
    }
    result.scene.commit();
    result.brute.commit(test::structure_named<SceneConfig>("brute"));
    return result;
}

Ray random_ray(test::Random& random) {
    const Aabb region(Point3(-25, -2, -25), Point3(25, 12, 25));
    Ray ray = random.ray_between(region, region);
    if (random.uniform() < 0.3) ray.t_max = random.uniform(0.0, 3.0);
    if (random.uniform() < 0.1) ray.t_min = random.uniform(0.0, 1.0);
    return ray;
}

TEST(Scene, IntersectAndOccludedAgreeWithBruteForceAndEachOther) {
    const RandomScene scenes = random_scene(3);
    test::Random random(4);
    QueryScratch scratch;
    int hits = 0;
    for (int i = 0; i < 20'000; ++i) {
        const Ray ray = random_ray(random);
        const auto expected = scenes.brute.intersect(ray, scratch);
        const auto actual = scenes.scene.intersect(ray, scratch);
        ASSERT_EQ(actual.has_value(), expected.has_value()) << i;
        EXPECT_EQ(scenes.scene.occluded(ray, scratch), expected.has_value()) << i;
        EXPECT_EQ(scenes.brute.occluded(ray, scratch), expected.has_value()) << i;
        if (!expected) continue;
        ++hits;
        EXPECT_EQ(actual->t, expected->t) << i;
        EXPECT_EQ(actual->object_id, expected->object_id) << i;
        EXPECT_EQ(actual->shape, expected->shape) << i;
        EXPECT_EQ(actual->geometric_normal, expected->geometric_normal) << i;
        // The object id names an object whose own query finds the same t.
        const auto own = scenes.scene.objects()[actual->object_id].shape->intersect(ray);
        ASSERT_TRUE(own) << i;
        EXPECT_EQ(own->t, actual->t) << i;
    }
    EXPECT_GT(hits, 8000);
}

TEST(Scene, CountedQueriesCountAndAgree) {
    const RandomScene scenes = random_scene(5);
    test::Random random(6);
    QueryScratch scratch;
    TraversalCounters counters;
    std::uint64_t valid = 0;
    for (int i = 0; i < 1000; ++i) {
        const Ray ray = random_ray(random);
        valid += is_valid(ray);
        const auto plain = scenes.brute.intersect(ray, scratch);
        const auto counted = scenes.brute.intersect_counted(ray, scratch, counters);
        ASSERT_EQ(plain.has_value(), counted.has_value());
        if (plain) {
            EXPECT_EQ(plain->t, counted->t);
        }
    }
    // Brute force tests all 300 bounded objects and the ground on every valid ray (random_ray
    // makes some with t_min > t_max, which are rejected before any test).
    EXPECT_GT(valid, 900u);
    EXPECT_EQ(counters.primitives_tested, valid * 301u);
}

using Shapes = std::vector<std::shared_ptr<const Shape>>;

// 20 spheres on a line, for the compounds below.
Shapes row_of_spheres() {
    Shapes spheres;
    for (int i = 0; i < 20; ++i)
        spheres.push_back(std::make_shared<Sphere>(Point3(3.0 * i, 0, 0), 1.0));
    return spheres;
}

// commit(config) builds the structures left to it below the objects: a build_at_commit compound
// that says "auto" gets the scene's structure name, one that names its own keeps it, and both get
// the scene's AcceleratorConfig, here one cell (max_resolution 1; a default grid over 20 members
// has many), however deep they sit (under an instance and a union, and shared by two objects).
// A compound built by its constructor keeps its structure; one queried before any commit is built
// then, with its own configuration, and a later commit leaves it alone.
TEST(Scene, CommitBuildsTheCompoundsLeftToItWithItsConfiguration) {
    CompoundConfig deferred;
    deferred.build_at_commit = true;
    CompoundConfig deferred_hgrid = deferred;
    deferred_hgrid.accelerator = "hgrid";
    auto left_auto = std::make_shared<const Compound>(row_of_spheres(), deferred);
    auto left_hgrid = std::make_shared<const Compound>(row_of_spheres(), deferred_hgrid);
    auto built = std::make_shared<const Compound>(row_of_spheres());
    auto queried = std::make_shared<const Compound>(row_of_spheres(), deferred);
    EXPECT_FALSE(left_auto->is_built());
    EXPECT_FALSE(queried->is_built());
    ASSERT_TRUE(queried->intersect(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)}));
    EXPECT_TRUE(queried->is_built());
    EXPECT_EQ(queried->accelerator_name(), "bvh");  // its own "auto": choose_accelerator

    Scene scene;
    const auto moved = Transform::translate(Vector3(0, 5, 0));
    scene.add_object(make_union({std::make_shared<Instance>(left_auto, moved), built}));
    scene.add_object(
        std::make_shared<Instance>(left_auto, Transform::translate(Vector3(0, 10, 0))));
    scene.add_object(left_hgrid);
    scene.add_object(std::make_shared<Instance>(queried, Transform::translate(Vector3(0, -5, 0))));
    SceneConfig config;
    config.accelerator = "grid";
    config.accelerator_config.grid.max_resolution = 1;
    config.accelerator_config.hierarchical_grid.max_resolution = 1;
    config.accelerator_config.hierarchical_grid.max_depth = 0;
    scene.commit(config);

    ASSERT_TRUE(left_auto->is_built());
    EXPECT_EQ(left_auto->accelerator_name(), "grid");
    EXPECT_EQ(left_auto->accelerator_stats().nodes, 1u);
    EXPECT_EQ(left_hgrid->accelerator_name(), "hgrid");
    EXPECT_EQ(left_hgrid->accelerator_stats().nodes, 1u);
    EXPECT_EQ(built->accelerator_name(), "bvh");
    EXPECT_EQ(queried->accelerator_name(), "bvh");
    // The same scene committed by default builds the grid it would over 20 members.
    auto left_default = std::make_shared<const Compound>(row_of_spheres(), deferred);
    Scene plain;
    plain.add_object(left_default);
    plain.commit(test::structure_named<SceneConfig>("grid"));
    EXPECT_EQ(left_default->accelerator_name(), "grid");
    EXPECT_GT(left_default->accelerator_stats().nodes, 1u);

    // Whatever built them, every compound answers as a loop over its spheres would.
    QueryScratch scratch;
    for (const double y : {-5.0, 0.0, 5.0, 10.0}) {
        for (int i = 0; i < 20; ++i) {
            const Ray ray{Point3(3.0 * i + 0.25, y + 4.0, 0.5), Vector3(0, -1, 0)};
            const std::optional<Hit> hit = scene.intersect(ray, scratch);
            ASSERT_TRUE(hit) << y << " " << i;
            // Down onto the sphere of radius 1 around (3 i, y, 0), at x offset 0.25, z 0.5: a
            // root good to a few ulps (1e-12 is 2^12 ulps of t = 3.2).
            EXPECT_NEAR(hit->t, 4.0 - std::sqrt(1.0 - 0.25 * 0.25 - 0.5 * 0.5), 1e-12) << y;
        }
    }
}

TEST(Scene, ConcurrentQueriesGiveTheSameAnswers) {
    const RandomScene scenes = random_scene(7);
    test::Random random(8);
    std::vector<Ray> rays;
    for (int i = 0; i < 8000; ++i) rays.push_back(random_ray(random));
    std::vector<std::optional<Hit>> expected(rays.size());
    std::vector<char> expected_occluded(rays.size());
    {
        QueryScratch scratch;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            expected[i] = scenes.scene.intersect(rays[i], scratch);
            expected_occluded[i] = scenes.scene.occluded(rays[i], scratch);
        }
    }
    std::vector<int> mismatches(4, 0);
    std::vector<std::thread> threads;
    for (int thread = 0; thread < 4; ++thread) {
        threads.emplace_back([&, thread] {
            QueryScratch scratch;
            for (int pass = 0; pass < 2; ++pass) {
                // Each thread walks the rays from a different start so they interleave.
                for (std::size_t k = 0; k < rays.size(); ++k) {
                    const std::size_t i = (k + thread * 2000) % rays.size();
                    const auto hit = scenes.scene.intersect(rays[i], scratch);
                    const bool occluded = scenes.scene.occluded(rays[i], scratch);
                    if (hit.has_value() != expected[i].has_value() ||
                        (hit &&
                         (hit->t != expected[i]->t || hit->object_id != expected[i]->object_id ||
                          hit->geometric_normal != expected[i]->geometric_normal)) ||
                        occluded != static_cast<bool>(expected_occluded[i]))
                        ++mismatches[thread];
                }
            }
        });
    }
    for (auto& thread : threads) thread.join();
    for (int thread = 0; thread < 4; ++thread) EXPECT_EQ(mismatches[thread], 0) << thread;
}

}  // namespace
}  // namespace csgrt
