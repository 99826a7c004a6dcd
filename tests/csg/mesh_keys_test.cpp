// The scene file's per-mesh shading and welding keys: "flat", "crease_degrees", "weld".

#include <gtest/gtest.h>

#include <filesystem>

#include "csgrt/mesh/mesh.h"
#include "csgrt/core/error.h"
#include "csgrt/csg/scene_file.h"

namespace csgrt {
namespace {

namespace fs = std::filesystem;
const fs::path kMeshes = fs::path(CSGRT_SOURCE_DIR) / "tests" / "data" / "meshes";

std::optional<Hit> hit_box(const Scene& scene, std::size_t object) {
    // box.off is [0,2] x [0,3] x [0,4]: a ray at a face near an edge.
    return scene.objects()[object].shape->intersect(
        Ray{Point3(1.9, 2.9, 10.0), Vector3(0.0, 0.0, -1.0)});
}

TEST(SceneMeshKeys, FlatAndCreaseShadeWithTheFaceAndSmoothDoesNot) {
    Scene scene = load_scene_from_string(R"({
      "objects": [
        {"type": "mesh", "path": "box.off"},
        {"type": "mesh", "path": "box.off", "flat": true},
        {"type": "mesh", "path": "box.off", "crease_degrees": 30},
        {"type": "mesh", "path": "box.off", "weld": true}
      ]
    })",
                                         "test.json", kMeshes);
    scene.commit();
    ASSERT_EQ(scene.objects().size(), 4u);
    const std::optional<Hit> smooth = hit_box(scene, 0), flat = hit_box(scene, 1),
                             creased = hit_box(scene, 2);
    ASSERT_TRUE(smooth && flat && creased);
    EXPECT_GT((smooth->shading_normal - smooth->geometric_normal).norm(), 1e-2);
    EXPECT_EQ(flat->shading_normal, flat->geometric_normal);
    EXPECT_NEAR((creased->shading_normal - creased->geometric_normal).norm(), 0.0, 1e-6);
    // Different settings are different meshes, not one cached load.
    EXPECT_NE(scene.objects()[0].shape.get(), scene.objects()[1].shape.get());
    EXPECT_TRUE(scene.objects()[3].shape->is_solid());
}

TEST(SceneMeshKeys, ACreaseOutsideItsRangeIsAnErrorAtTheKey) {
    for (const char* value : {"0", "-5", "181", "true"}) {
        const std::string text =
            std::string(R"({"objects": [{"type": "mesh", "path": "box.off", )") +
            R"("crease_degrees": )" + value + "}]}";
        try {
            load_scene_from_string(text, "test.json", kMeshes);
            ADD_FAILURE() << "accepted crease_degrees " << value;
        } catch (const std::exception& error) {
            EXPECT_NE(std::string(error.what()).find("crease_degrees"), std::string::npos)
                << error.what();
        }
    }
}

}  // namespace
}  // namespace csgrt
