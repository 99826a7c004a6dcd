// The cost AOV counts the work a camera ray causes at every level (core/query_cost.h,
// docs/rendering.md "Cost"): checked against counts known by construction on tiny scenes under
// brute force (which tests every primitive, so its counts follow from the scene alone), and on
// a scene that is one mesh, whose cost must depend on the mesh's own structure.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "csgrt/accel/factory.h"
#include "csgrt/core/error.h"
#include "csgrt/core/query_cost.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene.h"
#include "csgrt/mesh/mesh.h"
#include "csgrt/render/cost_layers.h"
#include "csgrt/render/exr.h"
#include "csgrt/render/renderer.h"
#include "render/scenes.h"
#include "support/meshes.h"

namespace csgrt {
namespace {

/// `shape` as the one object of a scene whose top-level structure is brute force.
Scene scene_of(std::shared_ptr<const Shape> shape) {
    Scene scene;
    scene.add_object(std::move(shape));
    SceneConfig config;
    config.accelerator = "brute";
    scene.commit(config);
    return scene;
}

/// The work of one centre-ray query as the renderer counts it: the top-level structure's
/// counters plus everything the cost scope saw below it.
QueryCost cost_of(const Scene& scene, const Ray& ray) {
    QueryScratch scratch;
    QueryCost cost;
    TraversalCounters counters;
    {
        const CostScope counting(scratch, cost);
        scene.intersect_counted(ray, scratch, counters);
    }
    EXPECT_EQ(scratch.cost(), nullptr);  // the scope is closed
    cost.nodes += counters.nodes_visited;
    cost.primitives += counters.primitives_tested;
    return cost;
}

Ray ray_along_z(double x, double y) {
    Ray ray;
    ray.origin = Point3(x, y, 10.0);
    ray.direction = Vector3(0.0, 0.0, -1.0);
    return ray;
}

TEST(Cost, ALeafIsOnePrimitiveTestAndOneSolveWhetherHitOrMissed) {
    const Scene scene = scene_of(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0));
    // Brute force over one object tests it on every ray; the sphere solves its quadratic.
    EXPECT_EQ(cost_of(scene, ray_along_z(0.2, 0.1)), (QueryCost{0, 1, 1}));
    EXPECT_EQ(cost_of(scene, ray_along_z(5.0, 5.0)), (QueryCost{0, 1, 1}));
    // An instance forwards to its shape: still one solve.
    const Scene moved = scene_of(std::make_shared<Instance>(
        std::make_shared<Sphere>(Point3(0, 0, 0), 1.0), Transform::translate(Vector3(3, 0, 0))));
    EXPECT_EQ(cost_of(moved, ray_along_z(3.0, 0.0)), (QueryCost{0, 1, 1}));
}

TEST(Cost, ACsgDifferenceCountsItsBoxTestsAndEachOperandsSpans) {
    // The unit box minus a ball at its corner (1, 1, 1) of radius 0.5.
    const Scene scene =
        scene_of(make_difference(std::make_shared<Box>(Point3(0, 0, 0), Point3(1, 1, 1)),
                                 {std::make_shared<Sphere>(Point3(1, 1, 1), 0.5)}));
    // Through both operands' boxes: the node's box, the subtracted operand's box (is it
    // crossed at all?), then that box again over the stretch the box's spans cover; the box's
    // and the ball's spans are one solve each.
    EXPECT_EQ(cost_of(scene, ray_along_z(0.9, 0.9)), (QueryCost{3, 1, 2}));
    // Through the box but not the ball's box (x < 0.5): the first operand's nearest hit alone.
    EXPECT_EQ(cost_of(scene, ray_along_z(0.2, 0.2)), (QueryCost{2, 1, 1}));
    // Missing the node's box: one box test and nothing below it.
    EXPECT_EQ(cost_of(scene, ray_along_z(2.0, 2.0)), (QueryCost{1, 1, 0}));
}

TEST(Cost, AMeshAsACsgOperandCountsItsEveryHitWalk) {
    // A sphere mesh (512 triangles, brute force) minus a ball of radius 0.5 at (1, 0, 0). Its
    // spans come from its structure's every-hit walk, which brute force makes over all 512
    // triangles; the CSG node's box tests and the ball's one solve are as for analytic
    // operands (ACsgDifferenceCountsItsBoxTestsAndEachOperandsSpans).
    const test::TestMesh sphere = test::sphere_mesh(3);
    const auto mesh_with = [&](const std::string& structure) {
        MeshConfig config;
        config.accelerator = structure;
        return std::make_shared<Mesh>(TriangleMeshData{sphere.vertices, sphere.triangles, {}},
                                      config);
    };
    const auto bitten = [&](const std::string& structure) {
        return scene_of(make_difference(mesh_with(structure),
                                        {std::make_shared<Sphere>(Point3(1, 0, 0), 0.5)}));
    };
    // Through both operands (x = 0.8 is inside the mesh: its faces are within 2% of the
    // unit sphere): the mesh's walk, 512 primitive tests, besides the scene's one.
    EXPECT_EQ(cost_of(bitten("brute"), ray_along_z(0.8, 0.0)), (QueryCost{3, 1 + 512, 1}));
    // Every other structure walks its nodes or cells and tests fewer triangles, but some.
    for (const std::string_view name : accelerator_names()) {
        if (name == "brute") continue;
        const QueryCost cost = cost_of(bitten(std::string(name)), ray_along_z(0.8, 0.0));
        EXPECT_GT(cost.nodes, 3u) << name;
        EXPECT_GT(cost.primitives, 1u) << name;
        EXPECT_LT(cost.primitives, 1u + 512u) << name;
        EXPECT_EQ(cost.solves, 1u) << name;
    }
}

TEST(Cost, ACompoundCountsItsBoxItsStructureAndItsChildren) {
    std::vector<std::shared_ptr<const Shape>> children;
    for (int i = 0; i < 3; ++i) {
        children.push_back(std::make_shared<Sphere>(Point3(3.0 * i, 0, 0), 1.0));
    }
    CompoundConfig config;
    config.accelerator = "brute";
    const Scene scene = scene_of(std::make_shared<Compound>(children, config));
    // The compound's box test, then its brute force over 3 children: three primitive tests
    // and three solves, besides the scene's one primitive test of the compound.
    EXPECT_EQ(cost_of(scene, ray_along_z(3.0, 0.0)), (QueryCost{1, 4, 3}));
    // Outside the compound's box: only that box test.
    EXPECT_EQ(cost_of(scene, ray_along_z(3.0, 5.0)), (QueryCost{1, 1, 0}));
}

TEST(Cost, ScopesNestAndCountNothingOnceClosed) {
    const Scene scene = scene_of(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0));
    QueryScratch scratch;
    QueryCost outer, inner;
    {
        const CostScope counting(scratch, outer);
        scene.intersect(ray_along_z(0, 0), scratch);
        {
            const CostScope nested(scratch, inner);
            scene.intersect(ray_along_z(0, 0), scratch);
            scene.occluded(ray_along_z(0, 0), scratch);
        }
        scene.occluded(ray_along_z(0, 0), scratch);
    }
    scene.intersect(ray_along_z(0, 0), scratch);
    // Uncounted queries under a scope count the top-level structure through the hook too.
    EXPECT_EQ(outer, (QueryCost{0, 2, 2}));
    EXPECT_EQ(inner, (QueryCost{0, 2, 2}));
}

/// A scene that is one closed mesh (a subdivided octahedron, 512 triangles) whose structure
/// is `structure`, under a brute-force top level, seen whole by the camera.
Scene one_mesh_scene(const std::string& structure) {
    const test::TestMesh sphere = test::sphere_mesh(3);
    MeshConfig config;
    config.accelerator = structure;
    Scene scene;
    scene.add_object(
        std::make_shared<Mesh>(TriangleMeshData{sphere.vertices, sphere.triangles, {}}, config));
    test::set_view(scene, Point3(0.3, 0.4, 4.0), Point3(0, 0, 0), 40.0);
    SceneConfig scene_config;
    scene_config.accelerator = "brute";
    scene.commit(scene_config);
    return scene;
}

TEST(Cost, ASceneThatIsOneMeshCostsWhatItsMeshStructureDoes) {
    RenderSettings settings = test::settings_of_size(16, 12);
    std::set<std::uint64_t> totals;
    std::uint64_t brute_total = 0;
    for (const std::string_view name : accelerator_names()) {
        const RenderResult result = render(one_mesh_scene(std::string(name)), settings);
        QueryCost sum;
        for (const Pixel& pixel : result.image.pixels()) {
            // The channels are counts and the total is their sum.
            EXPECT_EQ(pixel.cost, pixel.cost_nodes + pixel.cost_primitives + pixel.cost_solves);
            EXPECT_EQ(pixel.cost_solves, 0.0f) << name;  // triangles are tested, not solved
            if (name == "brute") {
                // Every pixel: the scene's test of the mesh, then each of its 512 triangles.
                EXPECT_EQ(pixel.cost_primitives, 513.0f);
                EXPECT_EQ(pixel.cost_nodes, 0.0f);
            }
            sum.nodes += static_cast<std::uint64_t>(pixel.cost_nodes);
            sum.primitives += static_cast<std::uint64_t>(pixel.cost_primitives);
            sum.solves += static_cast<std::uint64_t>(pixel.cost_solves);
        }
        // The statistics are the channels' sums; every hit is on the mesh.
        EXPECT_EQ(result.stats.centre_ray_cost, sum) << name;
        EXPECT_TRUE(result.stats.solves_by_kind.empty()) << name;
        ASSERT_GT(result.stats.primary_hits, 0u);
        EXPECT_EQ(result.stats.hits_by_leaf_kind,
                  (std::map<std::string, std::uint64_t>{{"mesh", result.stats.primary_hits}}));
        if (name == "brute") {
            brute_total = sum.total();
        } else {
            EXPECT_GT(sum.nodes, 0u) << name << " visits nodes or cells inside the mesh";
        }
        totals.insert(sum.total());
    }
    ASSERT_GT(brute_total, 0u);
    for (const std::uint64_t total : totals) EXPECT_LE(total, brute_total);
    // Each structure does different work: the cost is the mesh structure's, not a constant.
    EXPECT_EQ(totals.size(), accelerator_names().size());
}

TEST(Cost, SolvesByKindAddUpToTheSolvesAndHitsByLeafKindToTheHits) {
    Scene scene = test::csg_solids();  // a box, spheres and an instanced cylinder in CSG
    scene.commit();
    RenderSettings settings = test::settings_of_size(16, 12);
    const RenderStats stats = render(scene, settings).stats;
    std::uint64_t solves = 0, hits = 0;
    for (const auto& [kind, count] : stats.solves_by_kind) solves += count;
    for (const auto& [kind, count] : stats.hits_by_leaf_kind) hits += count;
    EXPECT_EQ(solves, stats.centre_ray_cost.solves);
    EXPECT_EQ(hits, stats.primary_hits);
    for (const char* kind : {"box", "sphere", "cylinder"}) {
        EXPECT_GT(stats.solves_by_kind.count(kind), 0u) << kind;
    }
}

TEST(CostLayers, EveryStructureOfTheSceneIsRebuiltAndSharedShapesStayShared) {
    const test::TestMesh sphere = test::sphere_mesh(2);
    MeshConfig mesh_config;
    mesh_config.accelerator = "bvh";
    const auto mesh = std::make_shared<Mesh>(
        TriangleMeshData{sphere.vertices, sphere.triangles, {}}, mesh_config);
    CompoundConfig compound_config;
    compound_config.accelerator = "brute";
    std::vector<std::shared_ptr<const Shape>> children = {
        std::make_shared<Instance>(mesh, Transform::translate(Vector3(-1.5, 0, 0))),
        std::make_shared<Instance>(mesh, Transform::translate(Vector3(1.5, 0, 0))),
        std::make_shared<Sphere>(Point3(0, 1.5, 0), 0.5)};
    Scene scene;
    scene.add_object(std::make_shared<Compound>(children, compound_config));
    // The mesh as a CSG operand too, under an instance.
    scene.add_object(
        make_difference(std::make_shared<Instance>(mesh, Transform::translate(Vector3(0, -1.5, 0))),
                        {std::make_shared<Sphere>(Point3(0.5, -1.5, 0.5), 0.6)}));
    test::set_view(scene, Point3(0.2, 0.3, 6.0), Point3(0, 0, 0));
    SceneConfig config;
    config.accelerator = "bvh";
    scene.commit(config);

    const Scene rebuilt = with_every_structure(scene, "grid");
    EXPECT_EQ(rebuilt.accelerator_name(), "grid");
    const auto& compound = dynamic_cast<const Compound&>(*rebuilt.objects()[0].shape);
    EXPECT_EQ(compound.accelerator_name(), "grid");
    const auto& first = dynamic_cast<const Instance&>(compound.child(0));
    const auto& second = dynamic_cast<const Instance&>(compound.child(1));
    const auto& new_mesh = dynamic_cast<const Mesh&>(first.shape());
    EXPECT_EQ(new_mesh.accelerator_stats().name, "grid");
    EXPECT_EQ(&second.shape(), &new_mesh);  // one mesh, rebuilt once, shared as before
    EXPECT_EQ(new_mesh.triangle_count(), mesh->triangle_count());
    // The leaf sphere has no structure below it: the same object.
    EXPECT_EQ(&compound.child(2),
              &dynamic_cast<const Compound&>(*scene.objects()[0].shape).child(2));
    const auto& difference = dynamic_cast<const Boolean&>(*rebuilt.objects()[1].shape);
    EXPECT_EQ(&dynamic_cast<const Instance&>(difference.first()).shape(), &new_mesh);
    EXPECT_GT(structure_build_milliseconds(rebuilt), 0.0);

    // The geometry is the same: every pixel's object and depth agree.
    RenderSettings settings = test::settings_of_size(12, 9);
    const Image before = render(scene, settings).image;
    const Image after = render(rebuilt, settings).image;
    int hits = 0;
    for (std::size_t i = 0; i < before.pixel_count(); ++i) {
        EXPECT_EQ(after.pixels()[i].object_id, before.pixels()[i].object_id) << i;
        EXPECT_EQ(after.pixels()[i].depth, before.pixels()[i].depth) << i;
        hits += before.pixels()[i].object_id != kNoIndex;
    }
    EXPECT_GT(hits, 20);
}

TEST(CostLayers, EachLayerIsTheCostOfTheSceneBuiltWithItsStructure) {
    const Scene scene = one_mesh_scene("bvh");
    RenderSettings settings = test::settings_of_size(8, 6);
    const std::vector<CostLayer> layers = cost_layers(scene, settings, {"brute", "grid"});
    ASSERT_EQ(layers.size(), 2u);
    EXPECT_EQ(layers[0].structure, "brute");
    EXPECT_EQ(layers[1].structure, "grid");
    for (const CostLayer& layer : layers) {
        EXPECT_EQ(layer.width, 8);
        ASSERT_EQ(layer.total.size(), 48u);
        EXPECT_GE(layer.build_milliseconds, 0.0);
        EXPECT_GT(layer.trace_milliseconds, 0.0);  // 48 rays through 512 triangles each
    }
    // Brute force at both levels: the scene's test of the mesh and its 512 triangles, everywhere.
    for (std::size_t i = 0; i < 48; ++i) {
        EXPECT_EQ(layers[0].primitives[i], 513.0f);
        EXPECT_EQ(layers[0].total[i], 513.0f);
    }
    EXPECT_EQ(cost_sum(layers[0]), 48u * 513u);
    // The grid layer is the render of the scene rebuilt with grids.
    const Image grid = render(with_every_structure(scene, "grid"), settings).image;
    for (std::size_t i = 0; i < 48; ++i) {
        EXPECT_EQ(layers[1].total[i], grid.pixels()[i].cost) << i;
        EXPECT_EQ(layers[1].nodes[i], grid.pixels()[i].cost_nodes) << i;
    }
    EXPECT_THROW(with_every_structure(scene, "no such structure"), InvalidParameter);

    // Written into the EXR beside the image's own cost and read back, build times included.
    const std::filesystem::path directory =
        std::filesystem::path(CSGRT_BINARY_DIR) / "test_output" / "cost_layers";
    std::filesystem::remove_all(directory);
    std::filesystem::create_directories(directory);
    write_exr(directory / "layers.exr", grid, ExrMetadata{}, layers);
    const ExrFile file = read_exr(directory / "layers.exr");
    ASSERT_EQ(file.cost_layers.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
        EXPECT_EQ(file.cost_layers[k].structure, layers[k].structure);
        EXPECT_EQ(file.cost_layers[k].build_milliseconds, layers[k].build_milliseconds);
        EXPECT_EQ(file.cost_layers[k].trace_milliseconds, layers[k].trace_milliseconds);
        EXPECT_EQ(file.cost_layers[k].total, layers[k].total);
        EXPECT_EQ(file.cost_layers[k].solves, layers[k].solves);
    }
    EXPECT_EQ(file.image.pixels()[5].cost, grid.pixels()[5].cost);
}

}  // namespace
}  // namespace csgrt
