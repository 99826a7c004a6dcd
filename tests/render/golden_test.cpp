// 64x64 golden images of canonical scenes, compared per pixel. To regenerate them on purpose
// (after a deliberate change to shading, sampling or a shape), see tests/golden/README.md:
//   CSGRT_UPDATE_GOLDEN=1 ./build/ci/tests/csgrt_tests --gtest_filter='Golden*'
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/exr.h"
#include "csgrt/render/renderer.h"
#include "render/scenes.h"

namespace csgrt {
namespace {

namespace fs = std::filesystem;

const fs::path kGoldenDirectory = fs::path(CSGRT_SOURCE_DIR) / "tests" / "golden";
const fs::path kScenes = fs::path(CSGRT_SOURCE_DIR) / "data" / "scenes";

bool updating_golden() {
    const char* value = std::getenv("CSGRT_UPDATE_GOLDEN");
    return value != nullptr && std::string(value) == "1";
}

/// The stated tolerance. Colour and alpha are stored as half (2^-11 relative rounding): two
/// half ulps of the larger of 1 and the value. Depth is float: 2^-20 relative (16 float ulps,
/// room for a different compiler's contraction of the double arithmetic). Normals: 2^-16.
/// Ids and cost exactly. A pixel outside this is an outlier; up to kMaxOutliers (0.05% of
/// 4096) are accepted, because a compiler or libm that rounds differently may flip a silhouette
/// sample from hit to miss; each outlier is printed.
constexpr int kMaxOutliers = 2;

bool pixel_matches(const Pixel& a, const Pixel& b) {
    auto colour_close = [](float x, float y) {
        return std::abs(x - y) <= 0x1.0p-10 * std::max({1.0f, std::abs(x), std::abs(y)});
    };
    auto depth_close = [](float x, float y) {
        if (std::isinf(x) || std::isinf(y)) return x == y;
        return std::abs(x - y) <= 0x1.0p-20 * std::max(std::abs(x), std::abs(y));
    };
    return colour_close(a.red, b.red) && colour_close(a.green, b.green) &&
           colour_close(a.blue, b.blue) && colour_close(a.alpha, b.alpha) &&
           depth_close(a.depth, b.depth) && std::abs(a.normal_x - b.normal_x) <= 0x1.0p-16 &&
           std::abs(a.normal_y - b.normal_y) <= 0x1.0p-16 &&
           std::abs(a.normal_z - b.normal_z) <= 0x1.0p-16 && a.object_id == b.object_id &&
           a.cost == b.cost;
}

struct GoldenCase {
    std::string name;
    std::function<Scene()> build;
    int samples_per_pixel;
};

std::vector<GoldenCase> golden_cases() {
    return {
        {"spheres_on_a_plane", test::spheres_on_a_plane, 4},
        {"csg_solids", test::csg_solids, 4},
        {"sphere_lattice_eye_light", [] { return test::sphere_lattice(4); }, 1},
        // The shipped scene files, through the loader (data/scenes, docs/scene-format.md).
        {"scene_showcase", [] { return load_scene(kScenes / "showcase.json"); }, 4},
        {"scene_part_objects", [] { return load_scene(kScenes / "part_objects.json"); }, 4},
    };
}

void PrintTo(const GoldenCase& golden, std::ostream* out) {
    *out << golden.name;
}

class Golden : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(Golden, MatchesTheStoredImage) {
    const GoldenCase& golden = GetParam();
    Scene scene = golden.build();
    SceneConfig config;
    config.accelerator = "brute";  // pinned: the cost channel depends on the structure
    scene.commit(config);
    RenderSettings settings = test::settings_of_size(64, 64);
    settings.samples_per_pixel = golden.samples_per_pixel;
    const Image image = render(scene, settings).image;
    const fs::path path = kGoldenDirectory / (golden.name + ".exr");

    if (updating_golden()) {
        ExrMetadata metadata;
        metadata.camera = scene.camera();
        metadata.accelerator = "brute";
        metadata.samples_per_pixel = golden.samples_per_pixel;
        metadata.scene = golden.name;
        write_exr(path, image, metadata);
        std::cout << "wrote " << path << '\n';
        return;
    }
    ASSERT_TRUE(fs::exists(path)) << path << " is missing; regenerate the golden images with "
                                  << "CSGRT_UPDATE_GOLDEN=1 (tests/golden/README.md)";
    // Through a write and read, so the fresh image is rounded to half like the stored one.
    const fs::path fresh = fs::path(CSGRT_BINARY_DIR) / "test_output" / (golden.name + ".exr");
    fs::create_directories(fresh.parent_path());
    write_exr(fresh, image, ExrMetadata{});
    const Image actual = read_exr(fresh).image;
    const Image expected = read_exr(path).image;
    ASSERT_EQ(actual.width(), expected.width());
    ASSERT_EQ(actual.height(), expected.height());
    int outliers = 0;
    for (int y = 0; y < expected.height(); ++y) {
        for (int x = 0; x < expected.width(); ++x) {
            const Pixel& a = actual.at(x, y);
            const Pixel& e = expected.at(x, y);
            if (pixel_matches(a, e)) continue;
            if (++outliers > 10) continue;  // the count says the rest
            std::cout << golden.name << " pixel " << x << ", " << y << ": rgba " << a.red << ' '
                      << a.green << ' ' << a.blue << ' ' << a.alpha << " vs " << e.red << ' '
                      << e.green << ' ' << e.blue << ' ' << e.alpha << ", depth " << a.depth
                      << " vs " << e.depth << ", id " << a.object_id << " vs " << e.object_id
                      << ", cost " << a.cost << " vs " << e.cost << '\n';
        }
    }
    EXPECT_LE(outliers, kMaxOutliers)
        << golden.name << ": " << outliers << " pixels outside the tolerance";
}

TEST(Showcase, EveryObjectIsInFrameAndNoneIsCutByTheEdge) {
    // The shipped showcase (docs/rendering.md, README): every bounded object shows, and none
    // reaches a border pixel, where the frame would cut it. Ids of the centre rays, 160 x 120
    // (the docs' aspect ratio): a pixel is 1/120 of the 38-degree field, finer than any gap.
    Scene scene = load_scene(kScenes / "showcase.json");
    scene.commit();
    RenderSettings settings = test::settings_of_size(160, 120);
    settings.max_depth = 0;
    const Image image = render(scene, settings).image;
    std::vector<bool> seen(scene.objects().size(), false);
    for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
            const std::uint32_t id = image.at(x, y).object_id;
            if (id == kNoIndex) continue;
            seen[id] = true;
            const bool border =
                x == 0 || y == 0 || x == image.width() - 1 || y == image.height() - 1;
            if (border && scene.objects()[id].shape->bounds().is_finite()) {
                ADD_FAILURE() << "object " << id << " (" << scene.objects()[id].name
                              << ") touches the edge at " << x << ", " << y;
            }
        }
    }
    for (std::size_t id = 0; id < seen.size(); ++id) {
        EXPECT_TRUE(seen[id]) << "object " << id << " (" << scene.objects()[id].name
                              << ") is not in frame";
    }
}

INSTANTIATE_TEST_SUITE_P(Canonical, Golden, ::testing::ValuesIn(golden_cases()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace csgrt
