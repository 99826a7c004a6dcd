// Replays, through the fuzz targets' own bodies (tests/fuzz/fuzz_harness.h), every input the
// fuzzers found to crash (tests/fuzz/regressions/<target>/, added by hand from scripts/fuzz's
// build/fuzz/crashes/) and every seed they start from, in every build: the asan preset turns a
// memory error here into a failure even without clang. Anything but the documented error type
// escaping the loader fails the test.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_harness.h"
#include "stress/summary.h"

namespace csgrt {
namespace {

const std::filesystem::path kSource = CSGRT_SOURCE_DIR;

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Files under `folders` (recursively) whose extension is `extension` (any if empty).
std::vector<std::filesystem::path> files_in(const std::vector<std::filesystem::path>& folders,
                                            const std::string& extension) {
    std::vector<std::filesystem::path> files;
    for (const auto& folder : folders) {
        if (!std::filesystem::exists(folder)) continue;
        for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
            if (!entry.is_regular_file() || entry.path().filename() == ".keep") continue;
            if (!extension.empty() && entry.path().extension() != "." + extension) continue;
            // The seeds scripts/fuzz uses: under 256 KiB.
            if (entry.file_size() >= 256 * 1024) continue;
            files.push_back(entry.path());
        }
    }
    return files;
}

TEST(FuzzRegression, SceneInputsGiveASceneOrASceneError) {
    int loaded = 0, replayed = 0;
    for (const auto& path : files_in({kSource / "tests/fuzz/regressions/scene"}, "")) {
        const std::vector<std::uint8_t> bytes = read_bytes(path);
        EXPECT_NO_THROW(
            fuzz::run_scene(std::string(bytes.begin(), bytes.end()), kSource / "data/scenes"))
            << path;
        ++replayed;
    }
    for (const auto& path :
         files_in({kSource / "data/scenes", kSource / "tests/data/scenes"}, "json")) {
        const std::vector<std::uint8_t> bytes = read_bytes(path);
        bool ok = false;
        EXPECT_NO_THROW(
            ok = fuzz::run_scene(std::string(bytes.begin(), bytes.end()), kSource / "data/scenes"))
            << path;
        // The shipped scenes are the fuzzer's valid seeds: they must load through the harness.
        if (path.parent_path() == kSource / "data/scenes") {
            EXPECT_TRUE(ok) << path;
        }
        loaded += ok;
        ++replayed;
    }
    EXPECT_GE(loaded, 3);
    std::printf("  %d scene inputs replayed, %d loaded\n", replayed, loaded);
    test::summarize("scene file inputs replayed", replayed, test::failed_assertions());
}

class FuzzRegressionMesh : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzRegressionMesh, InputsGiveAMeshOrAMeshError) {
    const std::string format = GetParam();
    int loaded = 0, replayed = 0;
    for (const auto& path : files_in({kSource / "tests/fuzz/regressions" / format, kSource / "data",
                                      kSource / "tests/data"},
                                     format)) {
        const std::vector<std::uint8_t> bytes = read_bytes(path);
        bool ok = false;
        EXPECT_NO_THROW(ok = fuzz::run_mesh(bytes, format)) << path;
        loaded += ok;
        ++replayed;
    }
    // tests/data/meshes holds a valid box in every format.
    EXPECT_GE(loaded, 1) << format;
    std::printf("  %d %s inputs replayed, %d loaded\n", replayed, format.c_str(), loaded);
    test::summarize(format + " inputs replayed", replayed, test::failed_assertions());
}

INSTANTIATE_TEST_SUITE_P(Formats, FuzzRegressionMesh, ::testing::Values("off", "obj", "ply", "stl"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace csgrt
