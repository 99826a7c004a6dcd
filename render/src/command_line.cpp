#include "csgrt/render/command_line.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "csgrt/accel/mesh.h"
#include "csgrt/core/instance.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/exr.h"
#include "csgrt/render/renderer.h"

namespace csgrt {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// A mistake in the command line; its message is the error line.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Newlines turned into spaces, so every error is one line.
std::string one_line(std::string text) {
    std::replace(text.begin(), text.end(), '\n', ' ');
    std::replace(text.begin(), text.end(), '\r', ' ');
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

std::string available_structures() {
    std::string list = "auto";
    for (std::string_view name : accelerator_names()) list.append(", ").append(name);
    return list;
}

void check_structure(const std::string& name) {
    if (name == "auto") return;
    const auto names = accelerator_names();
    if (std::find(names.begin(), names.end(), name) != names.end()) return;
    throw UsageError("--accel " + name +
                     ": unknown structure (available: " + available_structures() + ")");
}

void check_range(const char* option, long long value, long long low, long long high) {
    if (value < low || value > high) {
        throw UsageError(std::string(option) + " must be in [" + std::to_string(low) + ", " +
                         std::to_string(high) + "], got " + std::to_string(value));
    }
}

void check_scene_path(const fs::path& path) {
    std::error_code error;
    if (!fs::exists(path, error)) {
        throw UsageError("scene file '" + path.string() + "' does not exist");
    }
    if (fs::is_directory(path, error)) {
        throw UsageError("scene file '" + path.string() + "' is a directory");
    }
}

/// Fails early, before any work, for an output the writer could not produce.
void check_output_path(const fs::path& path) {
    if (path.extension() != ".exr") {
        throw UsageError("output '" + path.string() +
                         "' must end in .exr (the PNG previews are written beside it)");
    }
    const fs::path directory = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code error;
    if (!fs::is_directory(directory, error)) {
        throw UsageError("output directory '" + directory.string() + "' does not exist");
    }
    for (const fs::path& target : {path, colour_preview_path(path), cost_preview_path(path)}) {
        if (fs::is_directory(target, error)) {
            throw UsageError("output '" + target.string() + "' is a directory");
        }
    }
}

Scene load_checked(const std::string& scene_path) {
    check_scene_path(scene_path);
    return load_scene(scene_path);  // SceneError messages name the file and the place
}

/// A one-line progress bar on a terminal, drawn from worker threads at most ten times a
/// second and only once the render has run for `delay` (short renders stay silent).
class ProgressBar {
public:
    ProgressBar(std::ostream& err, bool enabled, double delay_seconds)
        : err_(err), enabled_(enabled), delay_(std::chrono::duration<double>(delay_seconds)) {}

    void update(double fraction) {
        if (!enabled_) return;
        std::unique_lock lock(mutex_, std::try_to_lock);
        if (!lock.owns_lock()) return;  // another thread is drawing
        const Clock::time_point now = Clock::now();
        if (now - start_ < delay_) return;
        if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
        last_draw_ = now;
        drawn_ = true;
        const double elapsed = std::chrono::duration<double>(now - start_).count();
        const int filled = static_cast<int>(fraction * kWidth);
        char line[128];
        std::snprintf(line, sizeof(line), "\r[%s%s] %3d%%  %.0f s, about %.0f s left",
                      std::string(filled, '#').c_str(), std::string(kWidth - filled, '.').c_str(),
                      static_cast<int>(fraction * 100.0), elapsed,
                      fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0);
        err_ << line << std::flush;
    }

    /// Clears the bar's line, if one was drawn.
    void finish() {
        std::lock_guard lock(mutex_);
        if (drawn_) err_ << '\r' << std::string(kWidth + 40, ' ') << '\r' << std::flush;
        drawn_ = false;
    }

private:
    static constexpr int kWidth = 40;
    std::ostream& err_;
    bool enabled_;
    std::chrono::duration<double> delay_;
    std::mutex mutex_;
    Clock::time_point start_ = Clock::now();
    Clock::time_point last_draw_;
    bool drawn_ = false;
};

struct RenderOptions {
    std::string scene;
    std::string output;
    int width = 640;
    int height = 480;
    int samples_per_pixel = 1;
    int threads = 0;
    std::string accelerator = "auto";
};

void render_command(const RenderOptions& options, CommandLineStreams streams) {
    check_range("--width", options.width, 1, kMaxImageSize);
    check_range("--height", options.height, 1, kMaxImageSize);
    check_range("--spp", options.samples_per_pixel, 1, kMaxSamplesPerPixel);
    check_range("--threads", options.threads, 0, 1024);
    check_structure(options.accelerator);
    const fs::path output = options.output;
    check_output_path(output);

    Scene scene = load_checked(options.scene);
    SceneConfig config;
    config.accelerator = options.accelerator;
    scene.commit(config);

    RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.samples_per_pixel = options.samples_per_pixel;
    settings.threads = options.threads;
    ProgressBar bar(streams.err, streams.err_is_terminal, streams.progress_delay_seconds);
    settings.progress = [&bar](double fraction) { bar.update(fraction); };
    const RenderResult result = render(scene, settings);
    bar.finish();

    const AcceleratorStats structure = scene.accelerator_stats();
    ExrMetadata metadata;
    metadata.camera = scene.camera();
    metadata.accelerator = std::string(scene.accelerator_name());
    metadata.accelerator_build_milliseconds = structure.build_milliseconds;
    metadata.samples_per_pixel = options.samples_per_pixel;
    metadata.scene = fs::path(options.scene).filename().string();
    write_render_files(output, result.image, metadata);

    std::ostringstream summary;
    summary.setf(std::ios::fixed);
    summary.precision(3);
    summary << options.scene << ": " << options.width << 'x' << options.height << ", "
            << options.samples_per_pixel << " spp in " << result.stats.seconds << " s, ";
    summary.precision(2);
    summary << result.stats.million_rays_per_second() << " Mrays/s (" << result.stats.primary_rays
            << " primary + " << result.stats.shadow_rays << " shadow rays); structure "
            << metadata.accelerator << " over " << scene.objects().size() << " objects, built in ";
    summary.precision(3);
    summary << structure.build_milliseconds << " ms; wrote " << output.string() << ", "
            << colour_preview_path(output).string() << ", " << cost_preview_path(output).string();
    streams.out << summary.str() << '\n';
}

/// Counts every shape in the tree under `shape` by kind(), descending through instances,
/// booleans and compounds; a shape shared by several parents counts once per use. Meshes add
/// their triangles to `triangles`, and the closed ones (solids) count in `closed_meshes`.
void count_kinds(const Shape& shape, std::map<std::string, std::size_t>& counts,
                 std::size_t& triangles, std::size_t& closed_meshes) {
    const std::string_view kind = shape.kind();
    ++counts[std::string(kind)];
    if (kind == "mesh") {
        if (const auto* mesh = dynamic_cast<const Mesh*>(&shape)) {
            triangles += mesh->triangle_count();
            closed_meshes += mesh->report().is_closed ? 1 : 0;
        }
    } else if (kind == "instance") {
        if (const auto* instance = dynamic_cast<const Instance*>(&shape)) {
            count_kinds(instance->shape(), counts, triangles, closed_meshes);
        }
    } else if (kind == "union" || kind == "intersection" || kind == "difference") {
        if (const auto* node = dynamic_cast<const Boolean*>(&shape)) {
            count_kinds(node->first(), counts, triangles, closed_meshes);
            count_kinds(node->second(), counts, triangles, closed_meshes);
        }
    } else if (kind == "compound") {
        if (const auto* compound = dynamic_cast<const Compound*>(&shape)) {
            for (const auto& child : compound->children()) {
                count_kinds(*child, counts, triangles, closed_meshes);
            }
        }
    }
}

std::string describe(const Vector3& v) {
    std::ostringstream text;
    text.precision(6);
    text << '(' << v.x() << ", " << v.y() << ", " << v.z() << ')';
    return text.str();
}

void info_command(const std::string& scene_path, CommandLineStreams streams) {
    Scene scene = load_checked(scene_path);
    scene.commit();  // "auto": what a render without --accel would build
    std::map<std::string, std::size_t> counts;
    std::size_t unbounded = 0, triangles = 0, closed_meshes = 0;
    for (const SceneObject& object : scene.objects()) {
        count_kinds(*object.shape, counts, triangles, closed_meshes);
        if (!object.shape->bounds().is_finite()) ++unbounded;
    }
    std::size_t shapes = 0;
    for (const auto& [kind, count] : counts) shapes += count;
    std::ostream& out = streams.out;
    out << "scene:      " << scene_path << '\n';
    out << "objects:    " << scene.objects().size() << " top-level (" << unbounded
        << " unbounded), " << shapes << " shapes in the trees under them:\n";
    for (const auto& [kind, count] : counts) {
        char row[96];
        std::snprintf(row, sizeof(row), "  %-18s %zu", kind.c_str(), count);
        out << row;
        if (kind == "mesh") out << " (" << triangles << " triangles in all)";
        out << '\n';
    }
    if (const auto meshes = counts.find("mesh"); meshes != counts.end()) {
        out << "meshes:     " << closed_meshes << " closed (solids: CSG operands, inside/outside), "
            << meshes->second - closed_meshes << " open\n";
    }
    std::size_t point_lights = 0;
    for (const Light& light : scene.lights())
        point_lights += std::holds_alternative<PointLight>(light);
    out << "materials:  " << scene.materials().size() << " (including \"default\")\n";
    out << "lights:     " << scene.lights().size() << " (" << point_lights << " point, "
        << scene.lights().size() - point_lights << " directional)"
        << (scene.lights().empty() ? "; rendered with an eye light" : "") << '\n';
    const Camera& camera = scene.camera();
    out << "camera:     "
        << (camera.projection == Camera::Projection::Pinhole ? "pinhole" : "orthographic") << " at "
        << describe(camera.position) << " looking at " << describe(camera.look_at);
    if (camera.projection == Camera::Projection::Pinhole) {
        out << ", " << camera.vertical_fov_degrees << " degrees vertical field of view\n";
    } else {
        out << ", " << camera.orthographic_height << " units high\n";
    }
    const Aabb& bounds = scene.bounds();
    if (bounds.is_empty()) {
        out << "bounds:     none (no bounded objects)\n";
    } else {
        out << "bounds:     " << describe(bounds.lower) << " to " << describe(bounds.upper) << '\n';
    }
    out << "structure:  " << scene.accelerator_name() << " (auto: " << scene.accelerator_reason()
        << ")\n";
}

void validate_command(const std::string& scene_path) {
    Scene scene = load_checked(scene_path);
    scene.commit();
}

}  // namespace

int run_csgrt(int argc, const char* const* argv, CommandLineStreams streams) {
    CLI::App app{
        "csgrt renders scenes of analytic shapes, CSG solids and meshes described in "
        "JSON (docs/scene-format.md), and checks them.",
        "csgrt"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "csgrt " CSGRT_VERSION);
    app.footer(
        "Examples:\n"
        "  csgrt render data/scenes/showcase.json -o out.exr --spp 16\n"
        "  csgrt info data/scenes/showcase.json\n"
        "  csgrt validate my_scene.json\n"
        "\n"
        "Run 'csgrt SUBCOMMAND --help' for a subcommand's options. Exit status: 0 on success, 1 "
        "on any error (one line on stderr).");

    RenderOptions options;
    CLI::App* render = app.add_subcommand("render", "Render a scene to an EXR with PNG previews");
    render->footer(
        "Writes OUT.exr with the channels R G B A (half, linear, premultiplied), Z (distance\n"
        "along the centre camera ray; inf for background), N.X N.Y N.Z (world normal), id\n"
        "(object index; 4294967295 for background) and cost (structure nodes visited plus\n"
        "primitives tested), and beside it OUT.png (colour, sRGB, clamped) and OUT.cost.png\n"
        "(cost in false colour). Prints one summary line: time, Mrays/s, the structure.");
    render->add_option("scene", options.scene, "The JSON scene file")
        ->required()
        ->type_name("SCENE.json");
    render->add_option("-o,--output", options.output, "The EXR file to write")
        ->required()
        ->type_name("OUT.exr");
    render
        ->add_option("--width", options.width,
                     "Image width in pixels, 1.." + std::to_string(kMaxImageSize))
        ->capture_default_str();
    render
        ->add_option("--height", options.height,
                     "Image height in pixels, 1.." + std::to_string(kMaxImageSize))
        ->capture_default_str();
    render
        ->add_option("--spp", options.samples_per_pixel,
                     "Samples per pixel on a stratified jittered grid, 1.." +
                         std::to_string(kMaxSamplesPerPixel))
        ->capture_default_str();
    render->add_option("--threads", options.threads, "Worker threads; 0 uses every core")
        ->capture_default_str();
    render
        ->add_option("--accel", options.accelerator,
                     "The structure over the scene's objects: " + available_structures() +
                         " ('csgrt info' shows what auto picks)")
        ->capture_default_str()
        ->type_name("NAME");

    std::string scene_path;
    CLI::App* info = app.add_subcommand("info", "Describe a scene and the structure 'auto' builds");
    info->footer(
        "Counts every shape by kind through the whole tree (instances, booleans, compounds;\n"
        "a shared shape once per use), and prints materials, lights, camera, world bounds\n"
        "and the structure 'auto' picks for the top-level objects, with the reason.");
    info->add_option("scene", scene_path, "The JSON scene file")
        ->required()
        ->type_name("SCENE.json");
    CLI::App* validate =
        app.add_subcommand("validate", "Check a scene file (errors only, exit 0 or 1)");
    validate->footer(
        "Loads and commits the scene. Prints nothing and exits 0 when it is usable; otherwise\n"
        "prints the first error (file, place in the file, what was expected) and exits 1.");
    validate->add_option("scene", scene_path, "The JSON scene file")
        ->required()
        ->type_name("SCENE.json");

    try {
        // CLI11 would report a mistyped subcommand as a missing one.
        const std::string first = argc > 1 ? argv[1] : "";
        if (!first.empty() && first[0] != '-' && first != "render" && first != "info" &&
            first != "validate") {
            throw UsageError("unknown subcommand '" + first +
                             "' (expected render, info or validate; see 'csgrt --help')");
        }
        try {
            app.parse(argc, argv);
        } catch (const CLI::Success& success) {
            return app.exit(success, streams.out, streams.err);  // --help, --version
        } catch (const CLI::ParseError& error) {
            throw UsageError(std::string(error.what()) + " (see 'csgrt --help')");
        }
        if (render->parsed()) {
            render_command(options, streams);
        } else if (info->parsed()) {
            info_command(scene_path, streams);
        } else {
            validate_command(scene_path);
        }
        return 0;
    } catch (const std::exception& error) {
        streams.out.flush();
        streams.err << "csgrt: error: " << one_line(error.what()) << std::endl;
        return 1;
    }
}

}  // namespace csgrt
