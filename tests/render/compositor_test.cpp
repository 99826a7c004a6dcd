// What a compositor gets from csgrt's files: the EXR read back by OpenImageIO's own tools
// (iinfo, oiiotool from Debian's openimageio-tools, which scripts/bootstrap installs), object
// names in the idManifest, and byte-identical files for identical renders.
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "csgrt/render/exr.h"
#include "csgrt/render/renderer.h"
#include "render/scenes.h"
#include "support/test_output.h"

namespace csgrt {
namespace {

using test::fresh_directory;

namespace fs = std::filesystem;

/// The full path of `tool` on PATH, or empty.
fs::path find_tool(const std::string& tool) {
    const char* path = std::getenv("PATH");
    std::stringstream directories(path ? path : "");
    std::string directory;
    while (std::getline(directories, directory, ':')) {
        const fs::path candidate = fs::path(directory) / tool;
        std::error_code error;
        if (fs::is_regular_file(candidate, error)) return candidate;
    }
    return {};
}

/// Runs `command` through the shell and returns its standard output; fails the test on a
/// non-zero status.
std::string run(const std::string& command) {
    std::string output;
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (!pipe) {
        ADD_FAILURE() << "cannot run " << command;
        return output;
    }
    std::array<char, 4096> buffer;
    while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) {
        output.append(buffer.data(), n);
    }
    const int status = ::pclose(pipe);
    EXPECT_EQ(status, 0) << command << ":\n" << output;
    return output;
}

/// The rendered test scene, with an id beyond float's exact integers (2^24 + 1) written into
/// one pixel, so a reader that turned ids into floats would be caught.
Image rendered_image() {
    Scene scene = test::spheres_on_a_plane();
    scene.commit();
    RenderSettings settings = test::settings_of_size(24, 16);
    Image image = render(scene, settings).image;
    image.at(0, 0).object_id = (1u << 24) + 1u;
    return image;
}

ExrMetadata metadata_of(const Scene& scene) {
    ExrMetadata metadata;
    metadata.camera = scene.camera();
    metadata.accelerator = "brute";
    metadata.objects = exr_objects(scene);
    metadata.scene = "spheres.json";
    return metadata;
}

/// Writes `image`, with the metadata of the test scene, to out.exr in a fresh directory
/// test_output/`directory_name`: the file given to OpenImageIO's tools. Returns its path.
fs::path written_exr(const std::string& directory_name, const Image& image) {
    const fs::path path = fresh_directory(directory_name) / "out.exr";
    write_exr(path, image, metadata_of(test::spheres_on_a_plane()));
    return path;
}

/// Why a test that needs OpenImageIO's `tool` skips without it.
std::string not_installed(const std::string& tool) {
    return tool + " not installed (openimageio-tools; scripts/bootstrap)";
}

/// oiiotool --dumpdata's pixel lines, per subimage: "Pixel (x, y): v0 v1 ..." -> values as text.
std::vector<std::map<std::pair<int, int>, std::vector<std::string>>> dumped_pixels(
    const std::string& dump) {
    std::vector<std::map<std::pair<int, int>, std::vector<std::string>>> subimages;
    std::istringstream lines(dump);
    std::string line;
    while (std::getline(lines, line)) {
        // With -a each subimage starts with a " subimage  N:" line; a one-part file has none.
        if (line.find(" subimage ") != std::string::npos) {
            subimages.emplace_back();
            continue;
        }
        int x = 0, y = 0, consumed = 0;
        const std::size_t at = line.find("Pixel (");
        if (at == std::string::npos) continue;
        if (subimages.empty()) subimages.emplace_back();
        if (std::sscanf(line.c_str() + at, "Pixel (%d, %d):%n", &x, &y, &consumed) != 2) continue;
        std::istringstream values(line.substr(at + consumed));
        std::vector<std::string> fields;
        std::string field;
        while (values >> field) fields.push_back(field);
        subimages.back()[{x, y}] = fields;
    }
    return subimages;
}

TEST(Compositor, ObjectNamesOfASceneGoIntoTheManifestInOrder) {
    Scene scene = test::spheres_on_a_plane();
    scene.add_object(std::make_shared<Sphere>(Point3(5, 1, 0), 0.5));  // unnamed, default material
    const std::vector<ExrObject> objects = exr_objects(scene);
    ASSERT_EQ(objects.size(), 5u);
    EXPECT_EQ(objects[0].name, "ground");
    EXPECT_EQ(objects[0].shape, "plane");
    EXPECT_EQ(objects[0].material, "default");
    EXPECT_EQ(objects[2].name, "middle");
    EXPECT_EQ(objects[2].material, "green");
    EXPECT_EQ(objects[4].name, "object 4");
    EXPECT_EQ(objects[4].shape, "sphere");
}

TEST(Compositor, IdenticalRendersGiveByteIdenticalFiles) {
    const fs::path directory = fresh_directory("compositor_identical");
    Scene scene = test::spheres_on_a_plane();
    scene.commit();
    RenderSettings settings = test::settings_of_size(32, 24);
    settings.samples_per_pixel = 4;
    for (const char* name : {"a.exr", "b.exr"}) {
        settings.threads = name[0] == 'a' ? 1 : 2;  // the schedule must not matter either
        const RenderResult result = render(scene, settings);
        ExrMetadata metadata = metadata_of(scene);
        metadata.accelerator_build_milliseconds = result.stats.seconds;  // differs: not written
        metadata.render_seconds = result.stats.seconds;
        write_render_files(directory / name, result.image, metadata);
    }
    for (const char* suffix : {".exr", ".png", ".cost.png"}) {
        const std::string a = test::file_contents(directory / (std::string("a") + suffix));
        ASSERT_FALSE(a.empty()) << suffix;
        EXPECT_TRUE(a == test::file_contents(directory / (std::string("b") + suffix))) << suffix;
    }
}

TEST(Compositor, OpenImageIoListsTheChannelsWithTheirTypes) {
    const fs::path iinfo = find_tool("iinfo");
    if (iinfo.empty()) GTEST_SKIP() << not_installed("iinfo");
    const fs::path exr = written_exr("compositor_iinfo", rendered_image());
    const std::string info = run(iinfo.string() + " -v -a " + exr.string());
    for (const char* expected :
         {"2 subimages",
          "channel list: R (half), G (half), B (half), A (half), Z (float), N.X (float), "
          "N.Y (float), N.Z (float), cost.nodes (float), cost.primitives (float), "
          "cost.solves (float), cost.total (float)",
          "1 channel, uint openexr", "channel list: id", "name: \"rgba\"", "name: \"id\"",
          "cameraPosition: 0.5, 2.5, 6", "scene: \"spheres.json\""}) {
        EXPECT_NE(info.find(expected), std::string::npos) << expected << " in:\n" << info;
    }
    EXPECT_EQ(info.find("acceleratorBuildMs"), std::string::npos) << info;
}

TEST(Compositor, OpenImageIoReadsEveryPixelAsWritten) {
    const fs::path oiiotool = find_tool("oiiotool");
    if (oiiotool.empty()) GTEST_SKIP() << not_installed("oiiotool");
    const Image image = rendered_image();
    const fs::path exr = written_exr("compositor_oiiotool", image);
    const auto subimages = dumped_pixels(run(oiiotool.string() + " -a --dumpdata " + exr.string()));
    ASSERT_EQ(subimages.size(), 2u);
    ASSERT_EQ(subimages[0].size(), image.pixel_count());
    ASSERT_EQ(subimages[1].size(), image.pixel_count());
    int background = 0;
    for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
            const Pixel& pixel = image.at(x, y);
            // The id part is read as uint, natively: "4294967295 (1)" for background, the
            // integer first, then OpenImageIO's normalised view of it in parentheses.
            const std::vector<std::string>& id = subimages[1].at({x, y});
            ASSERT_EQ(id.size(), 2u);
            EXPECT_EQ(std::stoull(id[0]), pixel.object_id) << x << ", " << y;
            // R G B A Z N.X N.Y N.Z and the cost layer, printed with 9 decimals: the half
            // colour and the float channels agree to the last printed digit (5e-10 absolute).
            const std::vector<std::string>& values = subimages[0].at({x, y});
            ASSERT_EQ(values.size(), 12u);
            const std::array<float, 12> expected = {float(half(pixel.red)),
                                                    float(half(pixel.green)),
                                                    float(half(pixel.blue)),
                                                    float(half(pixel.alpha)),
                                                    pixel.depth,
                                                    pixel.normal_x,
                                                    pixel.normal_y,
                                                    pixel.normal_z,
                                                    pixel.cost_nodes,
                                                    pixel.cost_primitives,
                                                    pixel.cost_solves,
                                                    pixel.cost};
            for (std::size_t c = 0; c < expected.size(); ++c) {
                if (std::isinf(expected[c])) {
                    EXPECT_EQ(values[c], "inf") << x << ", " << y << " channel " << c;
                    continue;
                }
                EXPECT_NEAR(std::stod(values[c]), expected[c],
                            5e-10 + 5e-10 * std::abs(expected[c]))
                    << x << ", " << y << " channel " << c;
            }
            if (pixel.object_id == kNoIndex) {
                ++background;
                EXPECT_EQ(values[4], "inf");  // background depth, as documented
            }
        }
    }
    EXPECT_GT(background, 0);  // the test image has sky to check
    EXPECT_EQ(subimages[1].at({0, 0})[0], "16777217");
}

TEST(Compositor, AnOpenImageIoCopyReadsBackTheSamePixels) {
    const fs::path oiiotool = find_tool("oiiotool");
    if (oiiotool.empty()) GTEST_SKIP() << not_installed("oiiotool");
    const Image image = rendered_image();
    const fs::path exr = written_exr("compositor_copy", image);
    const fs::path copied = exr.parent_path() / "copy.exr";
    // --native: without it oiiotool's image cache holds every part as float, and ids above
    // 2^24 come back rounded (docs/rendering.md).
    run(oiiotool.string() + " --native -a " + exr.string() + " -o " + copied.string());
    const ExrFile copy = read_exr(copied);
    ASSERT_EQ(copy.image.width(), image.width());
    ASSERT_EQ(copy.image.height(), image.height());
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        const Pixel& a = image.pixels()[i];
        const Pixel& b = copy.image.pixels()[i];
        ASSERT_EQ(b.red, float(half(a.red))) << i;
        ASSERT_EQ(b.alpha, float(half(a.alpha))) << i;
        ASSERT_EQ(b.depth, a.depth) << i;
        ASSERT_EQ(b.normal_y, a.normal_y) << i;
        ASSERT_EQ(b.cost, a.cost) << i;
        ASSERT_EQ(b.cost_solves, a.cost_solves) << i;
        ASSERT_EQ(b.object_id, a.object_id) << i;  // exact, 2^24 + 1 included
    }
    EXPECT_EQ(copy.metadata.camera.position, Point3(0.5, 2.5, 6.0));
}

}  // namespace
}  // namespace csgrt
