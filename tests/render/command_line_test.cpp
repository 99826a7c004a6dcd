#include "csgrt/render/command_line.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <iterator>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "csgrt/accel/factory.h"
#include "csgrt/render/exr.h"
#include "render/command_line_run.h"
#include "support/test_output.h"

namespace csgrt {
namespace {

using test::fresh_directory;
using test::kCommandLineScene;
using test::names_in;
using test::ProgramRun;
using test::run_program;

namespace fs = std::filesystem;

/// An error run: exit status `status` (1: the scene or the render failed; 2: a usage error),
/// nothing on stdout, exactly one line on stderr that starts with "csgrt: error: " and
/// contains `fragment`.
void expect_one_line_error(const ProgramRun& result, const std::string& fragment, int status = 1) {
    EXPECT_EQ(result.status, status);
    EXPECT_EQ(result.out, "");
    ASSERT_FALSE(result.err.empty());
    EXPECT_EQ(result.err.rfind("csgrt: error: ", 0), 0u) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_EQ(result.err.back(), '\n');
    EXPECT_NE(result.err.find(fragment), std::string::npos)
        << "\"" << fragment << "\" not in: " << result.err;
}

class CommandLine : public ::testing::Test {
protected:
    void SetUp() override {
        directory_ = fresh_directory(
            std::string("cli_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        scene_ = (directory_ / "scene.json").string();
        std::ofstream(scene_) << kCommandLineScene;
        output_ = (directory_ / "out.exr").string();
    }
    /// Only the scene file: no output, complete or partial, was left behind.
    void expect_no_output() const {
        EXPECT_EQ(names_in(directory_), std::vector<std::string>{"scene.json"});
    }

    fs::path directory_;
    std::string scene_;
    std::string output_;
};

TEST_F(CommandLine, RenderWritesTheExrAndPreviewsAndOneSummaryLine) {
    const ProgramRun result = run_program({"render", scene_, "-o", output_, "--width", "40",
                                           "--height", "30", "--spp", "4", "--threads", "2"});
    ASSERT_EQ(result.status, 0) << result.err;
    EXPECT_EQ(result.err, "");  // not a terminal: no progress bar
    EXPECT_EQ(std::count(result.out.begin(), result.out.end(), '\n'), 1) << result.out;
    for (const char* fragment : {"40x30", "4 spp", "Mrays/s", "primary", "shadow rays",
                                 "structure brute", "built in", "out.exr", "out.cost.png"}) {
        EXPECT_NE(result.out.find(fragment), std::string::npos) << fragment << ": " << result.out;
    }
    EXPECT_EQ(names_in(directory_),
              (std::vector<std::string>{"out.cost.png", "out.exr", "out.png", "scene.json"}));
    const ExrFile file = read_exr(output_);
    EXPECT_EQ(file.image.width(), 40);
    EXPECT_EQ(file.image.height(), 30);
    EXPECT_EQ(file.metadata.accelerator, "brute");
    EXPECT_EQ(file.metadata.samples_per_pixel, 4);
    EXPECT_EQ(file.metadata.scene, "scene.json");
    EXPECT_EQ(file.metadata.camera.position, Point3(0, 2, 6));
    // The scene's three objects all show up in the id channel.
    std::vector<bool> seen(3, false);
    for (const Pixel& pixel : file.image.pixels()) {
        if (pixel.object_id < 3) seen[pixel.object_id] = true;
    }
    EXPECT_EQ(seen, std::vector<bool>(3, true));
}

TEST_F(CommandLine, EveryAvailableStructureRendersTheSameImage) {
    ASSERT_EQ(run_program({"render", scene_, "-o", output_, "--width", "32", "--height", "24",
                           "--accel", "brute"})
                  .status,
              0);
    const ExrFile reference = read_exr(output_);
    for (std::string_view name : accelerator_names()) {
        const std::string other = (directory_ / (std::string(name) + ".exr")).string();
        ASSERT_EQ(run_program({"render", scene_, "-o", other, "--width", "32", "--height", "24",
                               "--accel", std::string(name)})
                      .status,
                  0)
            << name;
        const ExrFile file = read_exr(other);
        EXPECT_EQ(file.metadata.accelerator, name);
        for (std::size_t i = 0; i < file.image.pixel_count(); ++i) {
            const Pixel& a = reference.image.pixels()[i];
            const Pixel& b = file.image.pixels()[i];
            ASSERT_EQ(a.depth, b.depth) << name;
            ASSERT_EQ(a.object_id, b.object_id) << name;
            ASSERT_EQ(a.red, b.red) << name;
        }
    }
}

TEST_F(CommandLine, BadArgumentsGiveOneLineAndNoFiles) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{}, "subcommand is required"},
        {{"draw", scene_}, "draw"},
        {{"render", scene_}, "--output is required"},
        {{"render", "-o", output_}, "scene is required"},
        {{"render", scene_, "-o", output_, "--width", "0"},
         "--width: Value 0 not in range 1 to 16384"},
        {{"render", scene_, "-o", output_, "--height", "16385"},
         "--height: Value 16385 not in range 1 to 16384"},
        {{"render", scene_, "-o", output_, "--width", "-7"}, "--width"},
        {{"render", scene_, "-o", output_, "--width", "abc"}, "--width"},
        {{"render", scene_, "-o", output_, "--width", "99999999999"}, "--width"},
        {{"render", scene_, "-o", output_, "--spp", "0"}, "--spp: Value 0 not in range 1 to 4096"},
        {{"render", scene_, "-o", output_, "--spp", "4097"},
         "--spp: Value 4097 not in range 1 to 4096"},
        {{"render", scene_, "-o", output_, "--threads", "-1"}, "--threads"},
        {{"render", scene_, "-o", output_, "--accel", "octree"}, "octree not in {auto,"},
        {{"render", scene_, "-o", output_, "--bogus"}, "--bogus"},
        {{"render", scene_, "-o", output_, "--tonemap", "aces"}, "--tonemap aces: unknown curve"},
        {{"render", scene_, "-o", output_, "--exposure", "100"}, "--exposure must be in"},
        {{"render", (directory_ / "missing.json").string(), "-o", output_}, "missing.json"},
        {{"render", directory_.string(), "-o", output_}, "is actually a directory"},
        {{"render", scene_, "-o", (directory_ / "no" / "out.exr").string()}, "does not exist"},
        {{"render", scene_, "-o", (directory_ / "out.png").string()}, "must end in .exr"},
        {{"info"}, "scene is required"},
        {{"validate", (directory_ / "missing.json").string()}, "does not exist"},
    };
    for (const auto& [arguments, fragment] : cases) {
        SCOPED_TRACE(::testing::PrintToString(arguments));
        expect_one_line_error(run_program(arguments), fragment, 2);
    }
    expect_no_output();
}

TEST_F(CommandLine, StatsPrintsATableOfRaysHitsWorkAndTimes) {
    const ProgramRun result =
        run_program({"render", scene_, "-o", output_, "--width", "20", "--height", "10", "--accel",
                     "brute", "--stats", "--tonemap", "reinhard"});
    ASSERT_EQ(result.status, 0) << result.err;
    for (const char* fragment :
         {"Rays", "camera", "shadow", "% blocked", "Camera-ray hits", "Top-level structure (brute)",
          "primitives tested", "Every level", "box tests", "primitive tests", "root solves", "Time",
          "load scene", "commit", "render", "write files"}) {
        EXPECT_NE(result.out.find(fragment), std::string::npos) << fragment << ": " << result.out;
    }
    // 200 camera rays at 1 spp, their count printed in the table as in the summary line.
    EXPECT_NE(result.out.find("camera                                  200"), std::string::npos)
        << result.out;
    // Without --timing-in-header the EXR holds no timing; with it, it does.
    EXPECT_FALSE(read_exr(output_).metadata.include_timing);
    ASSERT_EQ(run_program({"render", scene_, "-o", output_, "--width", "8", "--height", "8",
                           "--timing-in-header"})
                  .status,
              0);
    EXPECT_TRUE(read_exr(output_).metadata.include_timing);
    EXPECT_EQ(read_exr(output_).metadata.objects.size(), 3u);
}

TEST_F(CommandLine, CostAllWritesALayerPerStructureAndTheirContactSheet) {
    const ProgramRun result = run_program({"render", scene_, "-o", output_, "--width", "12",
                                           "--height", "8", "--cost-all", "--stats"});
    ASSERT_EQ(result.status, 0) << result.err;
    EXPECT_EQ(names_in(directory_), (std::vector<std::string>{"out.cost-all.png", "out.cost.png",
                                                              "out.exr", "out.png", "scene.json"}));
    EXPECT_NE(result.out.find("out.cost-all.png"), std::string::npos) << result.out;
    const ExrFile file = read_exr(output_);
    std::vector<std::string> structures;
    for (const CostLayer& layer : file.cost_layers) {
        structures.push_back(layer.structure);
        EXPECT_EQ(layer.total.size(), 96u);
        EXPECT_NE(result.out.find("  " + layer.structure + " "), std::string::npos)
            << layer.structure << " in the statistics:\n"
            << result.out;
    }
    std::vector<std::string> expected(accelerator_names().begin(), accelerator_names().end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(structures, expected);  // the file lists channels alphabetically
    EXPECT_NE(result.out.find("Every structure at every level"), std::string::npos);
    EXPECT_NE(result.out.find("cost of every structure"), std::string::npos);
    // Progress on stderr, a line per structure in the registry's order, each with its times;
    // the traces' times are in the file too.
    std::size_t at = 0;
    for (std::size_t i = 0; i < accelerator_names().size(); ++i) {
        const std::string line = "cost of every structure: " + std::string(accelerator_names()[i]) +
                                 " (" + std::to_string(i + 1) + " of " +
                                 std::to_string(accelerator_names().size()) + ") ... built in ";
        at = result.err.find(line, at);
        ASSERT_NE(at, std::string::npos) << line << " in:\n" << result.err;
    }
    for (const CostLayer& layer : file.cost_layers) EXPECT_GT(layer.trace_milliseconds, 0.0);
}

TEST_F(CommandLine, EveryDocumentedStructureRendersTheSameImage) {
    // docs/rendering.md and --help name these; each must be registered and render the scene
    // (pixel-level equality of the structures is checked in renderer_test.cpp).
    for (const char* name : {"brute", "bvh", "grid", "hgrid", "rayclass"}) {
        const ProgramRun rendered = run_program(
            {"render", scene_, "-o", output_, "--width", "8", "--height", "8", "--accel", name});
        EXPECT_EQ(rendered.status, 0) << name << ": " << rendered.err;
        EXPECT_TRUE(fs::exists(output_)) << name;
        fs::remove(output_);
        fs::remove(fs::path(output_).replace_extension(".png"));
        fs::remove(fs::path(output_).replace_extension(".cost.png"));
    }
    expect_no_output();
}

TEST_F(CommandLine, ABrokenSceneFileIsOneLineNamingTheFileAndWritesNothing) {
    const std::string broken = (directory_ / "broken.json").string();
    std::ofstream(broken) << R"({"objects": [{"type": "sphere", "radius": -1}]})";
    const ProgramRun rendered = run_program({"render", broken, "-o", output_});
    expect_one_line_error(rendered, "broken.json");
    expect_one_line_error(rendered, "radius");
    expect_one_line_error(run_program({"validate", broken}), "/objects/0/radius");
    expect_one_line_error(run_program({"info", broken}), "broken.json");
    fs::remove(broken);
    expect_no_output();
}

TEST_F(CommandLine, AnOutputThatIsADirectoryIsRefusedBeforeRendering) {
    fs::create_directory(directory_ / "out.png");
    expect_one_line_error(run_program({"render", scene_, "-o", output_}), "is a directory", 2);
    EXPECT_EQ(names_in(directory_), (std::vector<std::string>{"out.png", "scene.json"}));
}

TEST_F(CommandLine, AnOutputThatIsTheSceneIsRefusedInEverySpelling) {
    // A scene named .exr (valid JSON): rendering onto it would replace the scene.
    const fs::path scene = directory_ / "scene.exr";
    std::ofstream(scene) << kCommandLineScene;
    const fs::path other_spelling = directory_ / ".." / directory_.filename() / "." / "scene.exr";
    fs::create_symlink(scene, directory_ / "link.exr");
    for (const fs::path& output : {scene, other_spelling, directory_ / "link.exr"}) {
        const ProgramRun result = run_program({"render", scene.string(), "-o", output.string()});
        expect_one_line_error(result, "is the scene file", 2);  // a usage error
    }
    std::ifstream in(scene);
    const std::string kept{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT_EQ(kept, kCommandLineScene);
    fs::remove(scene);
    fs::remove(directory_ / "link.exr");
    expect_no_output();
}

TEST_F(CommandLine, AnUnwritableOutputFolderIsRefusedBeforeRendering) {
    // The folder is tried by making a file in it, not by its permission bits, which root
    // passes: so each case below fails for root too, except the permission bits themselves.
    // The folder is a regular file, or a folder on its path is.
    std::ofstream(directory_ / "file.txt") << "x";
    expect_one_line_error(
        run_program({"render", scene_, "-o", (directory_ / "file.txt" / "out.exr").string()}),
        "file.txt' is not a directory", 2);
    expect_one_line_error(run_program({"render", scene_, "-o",
                                       (directory_ / "file.txt" / "sub" / "out.exr").string()}),
                          "sub' is not a directory: a folder on its path is a file", 2);
    // sysfs takes no new files, whoever asks (EACCES, or EROFS where it is mounted read-only).
    if (fs::is_directory("/sys")) {
        expect_one_line_error(run_program({"render", scene_, "-o", "/sys/out.exr"}),
                              "output directory '/sys' is not writable: ", 2);
        EXPECT_FALSE(fs::exists("/sys/out.exr"));
    }
    // Permission bits, which stop everyone but root.
    const fs::path folder = directory_ / "read_only";
    fs::create_directory(folder);
    fs::permissions(folder, fs::perms::owner_read | fs::perms::owner_exec);
    if (::geteuid() != 0) {
        const ProgramRun result =
            run_program({"render", scene_, "-o", (folder / "out.exr").string()});
        expect_one_line_error(result, "' is not writable: Permission denied", 2);
    }
    fs::permissions(folder, fs::perms::owner_all);
    fs::remove(folder);
    fs::remove(directory_ / "file.txt");
    expect_no_output();
}

TEST_F(CommandLine, AnImageLargerThanMemoryIsRefusedWithTheEstimate) {
    // 640 x 480 pixels of 52 bytes (every channel) plus 16 for writing: 20,889,600 bytes,
    // 20 MiB rounded up, against a 1 MiB budget.
    const char* argv[] = {"csgrt", "render", scene_.c_str(), "-o", output_.c_str()};
    std::ostringstream out, err;
    CommandLineStreams streams{out, err};
    streams.memory_bytes = 1u << 20;
    EXPECT_EQ(run_csgrt(5, argv, streams), 2);  // a usage error: the size asked for
    EXPECT_NE(
        err.str().find("a 640x480 image needs about 20 MiB, more than the 1 MiB of memory free"),
        std::string::npos)
        << err.str();
    expect_no_output();
}

TEST_F(CommandLine, TemporaryFilesAreRemovedOnSigtermAndSigint) {
    for (const int signal : {SIGTERM, SIGINT}) {
        int ready[2];
        ASSERT_EQ(::pipe(ready), 0);
        const pid_t child = ::fork();
        ASSERT_GE(child, 0);
        if (child == 0) {
            // What write_render_files leaves while it writes (exr.cpp's names), then the signal.
            const TemporariesRemovedOnSignal guard(output_);
            const std::string pid = std::to_string(::getpid());
            std::ofstream(directory_ / (".out.exr.tmp-" + pid + "-0")) << "partial";
            std::ofstream(directory_ / (".out.png.tmp-" + pid + "-1")) << "partial";
            std::ofstream(directory_ / (".out.cost.png.tmp-" + pid + "-2")) << "partial";
            const char byte = 1;
            (void)!::write(ready[1], &byte, 1);
            ::pause();
            ::_exit(3);  // not reached: the signal ends the process
        }
        char byte = 0;
        ASSERT_EQ(::read(ready[0], &byte, 1), 1);
        ::close(ready[0]);
        ::close(ready[1]);
        ASSERT_EQ(::kill(child, signal), 0);
        int status = 0;
        ASSERT_EQ(::waitpid(child, &status, 0), child);
        // Killed by the signal itself, as without the handler, and nothing left behind.
        EXPECT_TRUE(WIFSIGNALED(status)) << status;
        EXPECT_EQ(WTERMSIG(status), signal);
        expect_no_output();
    }
}

TEST_F(CommandLine, InfoCountsAnExpansionOfAMillionLeavesWithoutWalkingIt) {
    // d_k = compound [d_{k-1}, d_{k-1}] over a sphere: 2^20 leaves, 21 distinct shapes.
    std::string text = R"({"definitions": {"d0": {"type": "sphere", "radius": 1})";
    for (int k = 1; k <= 20; ++k) {
        const std::string below = std::string("d").append(std::to_string(k - 1));
        // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
        text.append(", \"d").append(std::to_string(k));
        text.append(R"(": {"type": "compound", "children": [{"type": "ref", "definition": ")");
        text.append(below).append(R"("}, {"type": "ref", "definition": ")").append(below);
        text.append(R"("}]})");
    }
    std::ofstream(scene_, std::ios::trunc)
        << text << R"(}, "objects": [{"type": "ref", "definition": "d20"}]})";
    const ProgramRun result = run_program({"info", scene_});
    ASSERT_EQ(result.status, 0) << result.err;
    for (const char* fragment :
         {"2097151 shapes in the trees under them (1048576 leaves)",
          "  compound           1048575\n", "  sphere             1048576\n"}) {
        EXPECT_NE(result.out.find(fragment), std::string::npos) << fragment << "\n" << result.out;
    }
}

TEST_F(CommandLine, TheProgressBarAppearsOnATerminalOnlyAfterTheDelay) {
    auto run_on_terminal = [&](bool terminal, double delay) {
        const std::vector<std::string> arguments = {"csgrt",   "render", scene_,     "-o", output_,
                                                    "--width", "64",     "--height", "48"};
        std::vector<const char*> argv;
        for (const std::string& argument : arguments) argv.push_back(argument.c_str());
        std::ostringstream out, err;
        EXPECT_EQ(run_csgrt(static_cast<int>(argv.size()), argv.data(),
                            CommandLineStreams{out, err, terminal, delay}),
                  0);
        return err.str();
    };
    // The default delay (a second) is far longer than this render: silent.
    EXPECT_EQ(run_on_terminal(true, 1.0), "");
    // Not a terminal: silent whatever the delay.
    EXPECT_EQ(run_on_terminal(false, 0.0), "");
    // No delay: the bar is drawn, then its line is cleared for the summary.
    const std::string err = run_on_terminal(true, 0.0);
    EXPECT_NE(err.find("["), std::string::npos) << err;
    EXPECT_NE(err.find("%"), std::string::npos) << err;
    EXPECT_EQ(err.back(), '\r');
    EXPECT_EQ(err.find('\n'), std::string::npos);

    // --cost-all on a terminal with no delay: each structure's bar is drawn over its line,
    // cleared, and the line written again whole with its times.
    const std::vector<std::string> arguments = {
        "csgrt", "render", scene_, "-o", output_, "--width", "16", "--height", "12", "--cost-all"};
    std::vector<const char*> argv;
    for (const std::string& argument : arguments) argv.push_back(argument.c_str());
    std::ostringstream out, cost_err;
    ASSERT_EQ(run_csgrt(static_cast<int>(argv.size()), argv.data(),
                        CommandLineStreams{out, cost_err, true, 0.0}),
              0);
    const std::string text = cost_err.str();
    const std::string last = "cost of every structure: " + std::string(accelerator_names().back()) +
                             " (" + std::to_string(accelerator_names().size()) + " of " +
                             std::to_string(accelerator_names().size()) + ") ...";
    const std::size_t at = text.rfind(last);
    ASSERT_NE(at, std::string::npos) << text;
    EXPECT_NE(text.find("%", 0), std::string::npos) << text;  // bars were drawn
    EXPECT_NE(text.find(" built in ", at), std::string::npos) << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'),
              static_cast<std::ptrdiff_t>(accelerator_names().size()));
}

TEST_F(CommandLine, ValidatePrintsNothingForAGoodScene) {
    const ProgramRun result = run_program({"validate", scene_});
    EXPECT_EQ(result.status, 0);
    EXPECT_EQ(result.out, "");
    EXPECT_EQ(result.err, "");
}

TEST_F(CommandLine, InfoCountsKindsThroughTheTree) {
    const ProgramRun result = run_program({"info", scene_});
    ASSERT_EQ(result.status, 0) << result.err;
    // plane; difference(box, sphere); union(instance(sphere), sphere): 8 shapes.
    for (const char* fragment :
         {"3 top-level (1 unbounded), 8 shapes", "  box                1\n",
          "  difference         1\n", "  instance           1\n", "  plane              1\n",
          "  sphere             3\n", "  union              1\n", "2 (1 point, 1 directional)",
          "pinhole at (0, 2, 6)", "structure:  brute (auto: 2 bounded members"}) {
        EXPECT_NE(result.out.find(fragment), std::string::npos)
            << "\"" << fragment << "\" not in:\n"
            << result.out;
    }
}

TEST_F(CommandLine, InfoReportsTheShowcasesMeshWithItsTriangleCount) {
    // The triangle count from the OFF file's header ("OFF", then vertices faces edges), read
    // here independently of the mesh loader; the knot is all triangles.
    const fs::path scenes = fs::path(CSGRT_SOURCE_DIR) / "data" / "scenes";
    std::ifstream off(scenes / "meshes" / "trefoil.off");
    std::string magic;
    std::size_t vertices = 0, faces = 0;
    off >> magic >> vertices >> faces;
    ASSERT_EQ(magic, "OFF");
    ASSERT_GT(faces, 100u);
    const ProgramRun result = run_program({"info", (scenes / "showcase.json").string()});
    ASSERT_EQ(result.status, 0) << result.err;
    EXPECT_NE(result.out.find("  mesh               1 (" + std::to_string(faces) +
                              " triangles in all)\n"),
              std::string::npos)
        << result.out;
}

TEST_F(CommandLine, InfoSaysForEachMeshWhetherItIsClosed) {
    // A closed cube (six quads), the same cube with its top face missing, and the cube written
    // one vertex per face corner (an open soup unless welded): each distinct mesh gets a line
    // saying whether it is closed, and why not; the closed cube, used by two objects, once.
    const std::string corners =
        "-1 -1 -1\n1 -1 -1\n1 1 -1\n-1 1 -1\n-1 -1 1\n1 -1 1\n1 1 1\n-1 1 1\n";
    const std::vector<std::string> quads = {"0 3 2 1", "4 5 6 7", "0 1 5 4",
                                            "2 3 7 6", "1 2 6 5", "0 4 7 3"};
    {
        std::ofstream closed(directory_ / "cube.off"), open(directory_ / "open.off");
        closed << "OFF\n8 6 0\n" << corners;
        open << "OFF\n8 5 0\n" << corners;
        for (std::size_t f = 0; f < quads.size(); ++f) {
            closed << "4 " << quads[f] << "\n";
            if (f != 3) open << "4 " << quads[f] << "\n";
        }
        std::ofstream soup(directory_ / "soup.off");
        soup << "OFF\n24 6 0\n";
        std::istringstream rows(corners);
        std::vector<std::string> vertex(8);
        for (std::string& v : vertex) std::getline(rows, v);
        for (const std::string& quad : quads) {
            std::istringstream indices(quad);
            int index;
            while (indices >> index) soup << vertex[static_cast<std::size_t>(index)] << "\n";
        }
        for (int f = 0; f < 6; ++f)
            soup << "4 " << 4 * f << " " << 4 * f + 1 << " " << 4 * f + 2 << " " << 4 * f + 3
                 << "\n";
    }
    std::ofstream(scene_, std::ios::trunc) << R"({"objects": [
        {"type": "mesh", "path": "cube.off", "name": "cube"},
        {"type": "mesh", "path": "open.off", "name": "open box"},
        {"type": "mesh", "path": "cube.off", "transform": [{"translate": [3, 0, 0]}]},
        {"type": "mesh", "path": "soup.off"},
        {"type": "mesh", "path": "soup.off", "weld": true, "name": "welded"}]})";
    const ProgramRun result = run_program({"info", scene_});
    ASSERT_EQ(result.status, 0) << result.err;
    for (const char* fragment :
         {"meshes:     3 closed (solids: CSG operands, inside/outside), 2 open\n",
          "  \"cube\": off, 8 vertices, 12 triangles from 6 faces (6 polygons triangulated), 1 "
          "component, closed (volume 8)\n",
          "  \"open box\": off, 8 vertices, 10 triangles from 5 faces (5 polygons triangulated), "
          "1 component, open: 4 boundary and 0 non-manifold edges\n",
          "  object 3: off, 24 vertices, 12 triangles from 6 faces (6 polygons triangulated), 6 "
          "components, open: 24 boundary and 0 non-manifold edges\n",
          "  \"welded\": off, 8 vertices, 12 triangles from 6 faces (6 polygons triangulated), 16 "
          "vertices welded, 1 component, closed (volume 8)\n"}) {
        EXPECT_NE(result.out.find(fragment), std::string::npos)
            << "\"" << fragment << "\" not in:\n"
            << result.out;
    }
    // Four distinct meshes, four lines: the cube used twice is listed once.
    EXPECT_EQ(result.out.find("  object 2:"), std::string::npos) << result.out;

    const ProgramRun json = run_program({"info", scene_, "--json"});
    ASSERT_EQ(json.status, 0) << json.err;
    const nlohmann::json meshes = nlohmann::json::parse(json.out)["meshes"];
    ASSERT_EQ(meshes.size(), 4u) << meshes;
    const std::size_t objects[] = {0, 1, 3, 4};
    const bool closed[] = {true, false, false, true};
    const std::size_t boundary[] = {0, 4, 24, 0}, welded[] = {0, 0, 0, 16};
    for (std::size_t k = 0; k < 4; ++k) {
        EXPECT_EQ(meshes[k]["object"], objects[k]) << meshes[k];
        EXPECT_EQ(meshes[k]["closed"], closed[k]) << meshes[k];
        EXPECT_EQ(meshes[k]["boundary_edges"], boundary[k]) << meshes[k];
        EXPECT_EQ(meshes[k]["welded_vertices"], welded[k]) << meshes[k];
        EXPECT_NEAR(meshes[k]["volume"].get<double>(), closed[k] ? 8.0 : 0.0, 1e-12) << meshes[k];
    }
    EXPECT_EQ(meshes[0]["object_name"], "cube");
    EXPECT_EQ(meshes[3]["object_name"], "welded");
}

TEST_F(CommandLine, HelpAndVersionSucceed) {
    const ProgramRun help = run_program({"--help"});
    EXPECT_EQ(help.status, 0);
    for (const char* fragment : {"render", "info", "validate", "Examples:"}) {
        EXPECT_NE(help.out.find(fragment), std::string::npos) << fragment;
    }
    const ProgramRun render_help = run_program({"render", "--help"});
    EXPECT_EQ(render_help.status, 0);
    for (const char* fragment : {"--width", "--spp", "--threads", "--accel", "auto", "cost"}) {
        EXPECT_NE(render_help.out.find(fragment), std::string::npos) << fragment;
    }
    const ProgramRun version = run_program({"--version"});
    EXPECT_EQ(version.status, 0);
    EXPECT_EQ(version.out.rfind("csgrt ", 0), 0u);
}

TEST_F(CommandLine, TheProgramExitsWithStatusTwoOnUsageErrorsAndOneOnABrokenScene) {
    // The real binary, not the in-process entry point: exit statuses as a shell sees them.
    const fs::path program = fs::path(CSGRT_BINARY_DIR) / "render" / "csgrt";
    ASSERT_TRUE(fs::exists(program)) << program << " is built with the tests";
    auto status_of = [&](const std::string& arguments) {
        const std::string command = program.string() + " " + arguments + " 2>" +
                                    (directory_ / "stderr.txt").string() + " >/dev/null";
        const int raw = std::system(command.c_str());
        fs::remove(directory_ / "stderr.txt");
        return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    };
    EXPECT_EQ(status_of("render " + scene_ + " -o " + output_ + " --width 0"), 2);
    EXPECT_EQ(status_of("render " + scene_ + " -o " + output_ + " --accel nope"), 2);
    EXPECT_EQ(status_of("validate " + (directory_ / "none.json").string()), 2);
    EXPECT_EQ(status_of(""), 2);
    expect_no_output();
    const std::string broken = (directory_ / "broken.json").string();
    std::ofstream(broken) << R"({"objects": [{"type": "sphere", "radius": -1}]})";
    EXPECT_EQ(status_of("validate " + broken), 1);
    fs::remove(broken);
    EXPECT_EQ(status_of("validate " + scene_), 0);
    EXPECT_EQ(status_of("--help"), 0);
    EXPECT_EQ(status_of("render " + scene_ + " -o " + output_ + " --width 8 --height 8"), 0);
    EXPECT_TRUE(fs::exists(output_));
}

}  // namespace
}  // namespace csgrt
