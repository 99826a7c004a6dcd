// The idManifest of the EXR `csgrt render` writes, which names every object of the scene
// (issue 15: serialised in time linear in the objects, where OpenEXR's own serialiser took
// 4.5 s for 10^6), read back with OpenEXR's own Imf::IDManifest and compared with the scene
// file the objects came from.

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIDManifest.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "render/command_line_run.h"
#include "support/test_output.h"

namespace csgrt {
namespace {

namespace fs = std::filesystem;

TEST(CommandLineManifest, EveryObjectIsNamedAsTheSceneFileNamesIt) {
    const fs::path directory = test::fresh_directory("cli_manifest");
    // 3,000 objects side by side: unnamed ones (the manifest says "object N"), names of 300 to
    // 304 bytes sharing 300 (the string table then stores the shared length in two bytes),
    // one name used by many objects, short names, two shapes and three materials; the most
    // common strings get the short codes, every other string is used once.
    constexpr int kObjects = 3'000;
    const std::array<std::string, 3> materials = {"default", "red", "green"};
    std::vector<std::array<std::string, 3>> expected;
    std::ostringstream text;
    text << R"({"materials": {"red": {"albedo": [0.8, 0.2, 0.2]}, "green": {"albedo": 0.5}},)"
         << R"( "objects": [)";
    for (int i = 0; i < kObjects; ++i) {
        std::string name;
        if (i % 4 == 1) name = std::string(300, 'p') + std::to_string(i);
        if (i % 4 == 2) name = "twin";
        if (i % 4 == 3) name = "n" + std::to_string(i) + std::string(i % 7, 'x');
        const bool sphere = i % 5 != 0;
        text << (i ? ", " : "") << "{";
        if (!name.empty()) text << R"("name": ")" << name << R"(", )";
        if (sphere) {
            text << R"("type": "sphere", "center": [)" << 3 * i << R"(, 0, 0], "radius": 1)";
        } else {
            text << R"("type": "box", "lower": [)" << 3 * i << R"(, 0, 0], "upper": [)" << 3 * i + 1
                 << ", 1, 1]";
        }
        text << R"(, "material": ")" << materials[i % 3] << R"("})";
        expected.push_back({name.empty() ? "object " + std::to_string(i) : name,
                            sphere ? "sphere" : "box", materials[i % 3]});
    }
    text << "]}";
    const fs::path scene = directory / "many.json";
    std::ofstream(scene) << text.str();
    const fs::path output = directory / "many.exr";
    const test::ProgramRun run = test::run_program(
        {"render", scene.string(), "-o", output.string(), "--width", "4", "--height", "3"});
    ASSERT_EQ(run.status, 0) << run.err;

    Imf::MultiPartInputFile parts(output.c_str());
    ASSERT_EQ(parts.parts(), 2);
    ASSERT_TRUE(Imf::hasIDManifest(parts.header(1)));
    const Imf::IDManifest manifest(Imf::idManifest(parts.header(1)));
    ASSERT_EQ(manifest.size(), 1u);
    const Imf::IDManifest::ChannelGroupManifest& group = manifest[0];
    EXPECT_EQ(group.getChannels(), std::set<std::string>{"id"});
    EXPECT_EQ(group.getComponents(), (std::vector<std::string>{"name", "shape", "material"}));
    EXPECT_EQ(group.getLifetime(), Imf::IDManifest::LIFETIME_SHOT);
    EXPECT_EQ(group.getHashScheme(), Imf::IDManifest::NOTHASHED);
    EXPECT_EQ(group.getEncodingScheme(), Imf::IDManifest::ID_SCHEME);
    ASSERT_EQ(group.size(), std::size_t{kObjects});
    for (int i = 0; i < kObjects; ++i) {
        const auto entry = group.find(static_cast<std::uint64_t>(i));
        ASSERT_TRUE(entry != group.end()) << "no entry for id " << i;
        const std::vector<std::string>& names = entry.text();
        ASSERT_EQ(names.size(), 3u);
        EXPECT_EQ(names[0], expected[i][0]) << "id " << i;
        EXPECT_EQ(names[1], expected[i][1]) << "id " << i;
        EXPECT_EQ(names[2], expected[i][2]) << "id " << i;
    }
    fs::remove_all(directory);
}

}  // namespace
}  // namespace csgrt
