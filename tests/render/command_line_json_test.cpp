// The csgrt program's machine-readable output (--json for info and the render summary) and the
// pointers its --help gives to the installed docs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "csgrt/render/command_line.h"
#include "render/command_line_run.h"

namespace csgrt {
namespace {

using test::kCommandLineScene;
using test::ProgramRun;
using test::run_program;

namespace fs = std::filesystem;

class CommandLineJson : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = fs::path(CSGRT_BINARY_DIR) / "test_output" /
                     (std::string("cli_json_") +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(directory_);
        fs::create_directories(directory_);
        scene_ = (directory_ / "scene.json").string();
        std::ofstream(scene_) << kCommandLineScene;
    }
    fs::path directory_;
    std::string scene_;
};

TEST_F(CommandLineJson, InfoIsOneObjectWithTheCountsOfTheTree) {
    const ProgramRun result = run_program({"info", scene_, "--json"});
    ASSERT_EQ(result.status, 0) << result.err;
    EXPECT_EQ(result.err, "");
    const nlohmann::json info = nlohmann::json::parse(result.out);  // throws unless one object
    EXPECT_EQ(info["scene"], scene_);
    EXPECT_EQ(info["objects"]["top_level"], 3);
    EXPECT_EQ(info["objects"]["unbounded"], 1);
    EXPECT_EQ(info["objects"]["shapes"], 8);
    const nlohmann::json kinds = {{"box", 1},   {"difference", 1}, {"instance", 1},
                                  {"plane", 1}, {"sphere", 3},     {"union", 1}};
    EXPECT_EQ(info["kinds"], kinds);
    EXPECT_EQ(info["triangles"], 0);
    EXPECT_EQ(info["meshes"], nlohmann::json::array());  // entries: command_line_test.cpp
    EXPECT_EQ(info["materials"], 2);                     // "default" and "red"
    EXPECT_EQ(info["lights"]["point"], 1);
    EXPECT_EQ(info["lights"]["directional"], 1);
    EXPECT_EQ(info["camera"]["projection"], "pinhole");
    EXPECT_EQ(info["camera"]["position"], (nlohmann::json{{"x", 0}, {"y", 2}, {"z", 6}}));
    EXPECT_EQ(info["structure"]["name"], "brute");
    EXPECT_TRUE(info["structure"]["reason"].is_string());
    // The bounded objects: the difference's box [-1, 1] x [0, 2] x [-1, 1] and the union's
    // spheres reaching x = 2.4 and y = 1.2; the bounds are conservative, so they contain that.
    EXPECT_LE(info["bounds"]["lower"]["x"].get<double>(), -1.0);
    EXPECT_GE(info["bounds"]["upper"]["x"].get<double>(), 2.4);
    EXPECT_GE(info["bounds"]["upper"]["y"].get<double>(), 2.0);
}

TEST_F(CommandLineJson, TheRenderSummaryIsOneObjectWithTheRayCounts) {
    const std::string output = (directory_ / "out.exr").string();
    const ProgramRun result = run_program({"render", scene_, "-o", output, "--width", "40",
                                           "--height", "30", "--spp", "4", "--json"});
    ASSERT_EQ(result.status, 0) << result.err;
    const nlohmann::json summary = nlohmann::json::parse(result.out);
    EXPECT_EQ(summary["width"], 40);
    EXPECT_EQ(summary["height"], 30);
    EXPECT_EQ(summary["samples_per_pixel"], 4);
    // Four colour samples and the centre ray per pixel (docs/rendering.md).
    EXPECT_EQ(summary["primary_rays"], 40 * 30 * (4 + 1));
    EXPECT_GT(summary["shadow_rays"].get<double>(), 0.0);
    EXPECT_GT(summary["seconds"].get<double>(), 0.0);
    EXPECT_EQ(summary["structure"]["name"], "brute");
    EXPECT_EQ(summary["structure"]["objects"], 3);
    ASSERT_EQ(summary["outputs"].size(), 3u);
    for (const auto& file : summary["outputs"]) {
        EXPECT_TRUE(fs::exists(file.get<std::string>())) << file;
    }
}

TEST_F(CommandLineJson, UsageErrorsExitWithStatusTwoAndHelpNamesTheInstalledDocs) {
    const std::string output = (directory_ / "out.exr").string();
    EXPECT_EQ(run_program({"info", scene_, "--json", "--bogus"}).status, 2);
    EXPECT_EQ(run_program({"render", scene_, "-o", output, "--threads", "1025"}).status, 2);
    EXPECT_EQ(run_program({"info", (directory_ / "none.json").string()}).status, 2);
    const ProgramRun help = run_program({"--help"});
    EXPECT_EQ(help.status, 0);
    EXPECT_NE(help.out.find("man csgrt"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("share/doc/csgrt"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("2 for a usage error"), std::string::npos) << help.out;
}

}  // namespace
}  // namespace csgrt
