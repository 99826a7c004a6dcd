#pragma once

// The pieces of the csgrt program (run_csgrt, csgrt/render/command_line.h) that its sources
// share: the render command in command_line_render.cpp, info and validate in
// command_line_info.cpp, the statistics table in render_statistics.cpp. Private to render/src.

#include <iosfwd>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/command_line.h"
#include "csgrt/render/renderer.h"

namespace csgrt::command_line {

/// The exit status of a usage error (a bad option or argument, a missing file), as getopt-style
/// programs and CLI11's own parse errors use it; 1 is kept for a scene or render that fails.
constexpr int kUsageErrorStatus = 2;

/// A mistake in the command line; its message is the error line.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The scene file exists and is not a directory: its option's CLI::ExistingFile said so.
inline Scene load_checked(const std::string& scene_path) {
    return load_scene(scene_path);  // SceneError messages name the file and the place
}

/// "auto" and every name make_accelerator knows, comma separated.
std::string available_structures();

struct RenderOptions {
    std::string scene;
    std::string output;
    int width = 640;
    int height = 480;
    int samples_per_pixel = 1;
    int threads = 0;
    std::string accelerator = "auto";
    std::string tone_curve = "filmic";
    double exposure_stops = 0.0;
    bool timing_in_header = false;
    bool statistics = false;
    bool json = false;
    bool cost_all = false;
};

/// `csgrt render`: checks the options, loads, commits, renders, writes, prints the summary.
void render_command(const RenderOptions& options, CommandLineStreams streams);

/// The stages of a render in order (load, commit, render, the cost of every structure when
/// asked, write) with their seconds.
using StageSeconds = std::vector<std::pair<const char*, double>>;

/// The --stats table (docs/rendering.md, "Statistics"); `layers` are --cost-all's.
void print_statistics(std::ostream& out, const Scene& scene, const RenderStats& stats,
                      const StageSeconds& stage_seconds, std::span<const CostLayer> layers);

/// `csgrt info`, as text or (json) one JSON object.
void info_command(const std::string& scene_path, bool json, CommandLineStreams streams);

/// `csgrt validate`: loads and commits; throws what either throws.
void validate_command(const std::string& scene_path);

}  // namespace csgrt::command_line
