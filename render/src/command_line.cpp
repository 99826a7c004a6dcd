#include "csgrt/render/command_line.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <new>
#include <optional>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "csgrt/mesh/mesh.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/exr.h"
#include "csgrt/render/renderer.h"
#include "csgrt/render/tonemap.h"

namespace csgrt {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// The exit status of a usage error (a bad option or argument, a missing file), as getopt-style
/// programs and CLI11's own parse errors use it; 1 is kept for a scene or render that fails.
constexpr int kUsageErrorStatus = 2;

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

/// Fails early, before any work, for an output the writer could not produce or that would
/// replace the scene it renders.
void check_output_path(const fs::path& path, const fs::path& scene) {
    if (path.extension() != ".exr") {
        throw UsageError("output '" + path.string() +
                         "' must end in .exr (the PNG previews are written beside it)");
    }
    const fs::path directory = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code error;
    if (!fs::is_directory(directory, error)) {
        throw UsageError("output directory '" + directory.string() + "' does not exist");
    }
    if (::access(directory.c_str(), W_OK | X_OK) != 0) {
        throw UsageError("output directory '" + directory.string() +
                         "' is not writable: " + std::strerror(errno));
    }
    for (const fs::path& target : {path, colour_preview_path(path), cost_preview_path(path)}) {
        if (fs::is_directory(target, error)) {
            throw UsageError("output '" + target.string() + "' is a directory");
        }
        // equivalent() compares device and inode: another spelling, a symlink or a hard link
        // of the scene is the scene.
        if (fs::exists(target, error) && fs::equivalent(target, scene, error)) {
            throw UsageError("output '" + target.string() + "' is the scene file '" +
                             scene.string() + "'; rendering would overwrite it");
        }
    }
}

/// What the image of a render takes: the pixels (every channel), and while writing, the
/// previews' 8-bit rows and the EXR's half colour.
std::uint64_t image_bytes(int width, int height) {
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
    return pixels * (sizeof(Pixel) + 4 + 4 + 8);
}

std::string in_mebibytes(std::uint64_t bytes) {
    return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB";
}

/// The machine's free memory now, or `configured` when set.
std::uint64_t memory_available(std::uint64_t configured) {
    if (configured > 0) return configured;
    const long pages = ::sysconf(_SC_AVPHYS_PAGES);
    const long page_size = ::sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page_size <= 0) return std::numeric_limits<std::uint64_t>::max();
    return std::uint64_t(pages) * std::uint64_t(page_size);
}

/// The scene file exists and is not a directory: its option's CLI::ExistingFile said so.
Scene load_checked(const std::string& scene_path) {
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
    std::string tone_curve = "filmic";
    double exposure_stops = 0.0;
    bool timing_in_header = false;
    bool statistics = false;
    bool json = false;
};

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The --stats table, after POV-Ray's end-of-render statistics: rays by kind, hits by the
/// top-level objects' shape kinds, the top-level structure's work, time per stage.
void print_statistics(std::ostream& out, const Scene& scene, const RenderStats& stats,
                      const std::array<double, 4>& stage_seconds) {
    auto row = [&out](const char* label, std::uint64_t count, const std::string& note = {}) {
        char line[160];
        std::snprintf(line, sizeof(line), "  %-28s %14llu  %s", label,
                      static_cast<unsigned long long>(count), note.c_str());
        std::string text = line;
        while (!text.empty() && text.back() == ' ') text.pop_back();
        out << text << '\n';
    };
    auto percent = [](std::uint64_t part, std::uint64_t whole) {
        char text[32];
        std::snprintf(text, sizeof(text), "%.1f%%", whole ? 100.0 * part / whole : 0.0);
        return std::string(text);
    };
    out << "Rays\n";
    row("camera", stats.primary_rays, percent(stats.primary_hits, stats.primary_rays) + " hit");
    row("shadow", stats.shadow_rays,
        percent(stats.shadow_rays_blocked, stats.shadow_rays) + " blocked");
    row("mirror and glass", stats.secondary_rays);
    row("total", stats.primary_rays + stats.shadow_rays + stats.secondary_rays);
    out << "Camera-ray hits by the top-level object's shape\n";
    std::map<std::string, std::pair<std::size_t, std::uint64_t>> kinds;  // objects, hits
    for (std::size_t i = 0; i < scene.objects().size(); ++i) {
        auto& kind = kinds[std::string(scene.objects()[i].shape->kind())];
        ++kind.first;
        if (i < stats.hits_per_object.size()) kind.second += stats.hits_per_object[i];
    }
    for (const auto& [kind, count] : kinds) {
        row(kind.c_str(), count.second,
            std::to_string(count.first) + (count.first == 1 ? " object" : " objects"));
    }
    out << "Top-level structure (" << scene.accelerator_name() << "), centre rays\n";
    row("nodes or cells visited", stats.centre_ray_work.nodes_visited);
    row("primitives tested", stats.centre_ray_work.primitives_tested);
    row("boxes tested", stats.centre_ray_work.boxes_tested);
    out << "Time\n";
    const std::array<const char*, 4> stages = {"load scene", "commit (build structures)", "render",
                                               "write files"};
    for (std::size_t i = 0; i < stages.size(); ++i) {
        char line[96];
        std::snprintf(line, sizeof(line), "  %-28s %14.3f s\n", stages[i], stage_seconds[i]);
        out << line;
    }
}

/// {"x": .., "y": .., "z": ..} of a point or vector, for --json. (Its text is dumped with
/// invalid UTF-8 replaced, so a file name in any encoding prints.)
nlohmann::json json_of(const Vector3& v) {
    return {{"x", v.x()}, {"y", v.y()}, {"z", v.z()}};
}

void render_command(const RenderOptions& options, CommandLineStreams streams) {
    // --width, --height, --spp, --threads, --accel and the scene were checked by their
    // options' CLI11 validators.
    ToneMapping tone_mapping;
    try {
        tone_mapping.curve = parse_tone_curve(options.tone_curve);
    } catch (const InvalidParameter&) {
        throw UsageError("--tonemap " + options.tone_curve +
                         ": unknown curve (available: filmic, reinhard, clamp)");
    }
    if (!std::isfinite(options.exposure_stops) || std::abs(options.exposure_stops) > 64.0) {
        throw UsageError("--exposure must be in [-64, 64] stops");
    }
    tone_mapping.exposure_stops = options.exposure_stops;
    const fs::path output = options.output;
    check_output_path(output, options.scene);
    const std::uint64_t needed = image_bytes(options.width, options.height);
    const std::uint64_t available = memory_available(streams.memory_bytes);
    if (needed > available) {
        throw UsageError("a " + std::to_string(options.width) + "x" +
                         std::to_string(options.height) + " image needs about " +
                         in_mebibytes(needed) + ", more than the " + in_mebibytes(available) +
                         " of memory free here; render a smaller image");
    }

    std::array<double, 4> stage_seconds{};  // load, commit, render, write
    Clock::time_point stage_start = Clock::now();
    Scene scene = load_checked(options.scene);
    stage_seconds[0] = seconds_since(stage_start);
    stage_start = Clock::now();
    SceneConfig config;
    config.accelerator = options.accelerator;
    scene.commit(config);
    stage_seconds[1] = seconds_since(stage_start);

    RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.samples_per_pixel = options.samples_per_pixel;
    settings.threads = options.threads;
    ProgressBar bar(streams.err, streams.err_is_terminal, streams.progress_delay_seconds);
    settings.progress = [&bar](double fraction) { bar.update(fraction); };
    std::optional<RenderResult> rendered;
    try {
        rendered.emplace(render(scene, settings));
    } catch (const std::bad_alloc&) {
        bar.finish();
        throw UsageError("out of memory while rendering (the image alone needs about " +
                         in_mebibytes(needed) + ")");
    }
    const RenderResult& result = *rendered;
    bar.finish();

    const AcceleratorStats structure = scene.accelerator_stats();
    ExrMetadata metadata;
    metadata.camera = scene.camera();
    metadata.accelerator = std::string(scene.accelerator_name());
    metadata.accelerator_build_milliseconds = structure.build_milliseconds;
    metadata.samples_per_pixel = options.samples_per_pixel;
    metadata.scene = fs::path(options.scene).filename().string();
    metadata.include_timing = options.timing_in_header;
    metadata.render_seconds = result.stats.seconds;
    metadata.objects = exr_objects(scene);
    stage_start = Clock::now();
    {
        const TemporariesRemovedOnSignal guard(output);
        write_render_files(output, result.image, metadata, tone_mapping);
    }
    stage_seconds[2] = result.stats.seconds;
    stage_seconds[3] = seconds_since(stage_start);

    if (options.json) {
        const nlohmann::json summary = {
            {"scene", options.scene},
            {"width", options.width},
            {"height", options.height},
            {"samples_per_pixel", options.samples_per_pixel},
            {"seconds", result.stats.seconds},
            {"million_rays_per_second", result.stats.million_rays_per_second()},
            {"primary_rays", result.stats.primary_rays},
            {"shadow_rays", result.stats.shadow_rays},
            {"structure",
             {{"name", metadata.accelerator},
              {"objects", scene.objects().size()},
              {"build_milliseconds", structure.build_milliseconds}}},
            {"outputs",
             {output.string(), colour_preview_path(output).string(),
              cost_preview_path(output).string()}}};
        streams.out << summary.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)
                    << '\n';
        return;
    }
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
    if (options.statistics) print_statistics(streams.out, scene, result.stats, stage_seconds);
}

std::string describe(const Vector3& v) {
    std::ostringstream text;
    text.precision(6);
    text << '(' << v.x() << ", " << v.y() << ", " << v.z() << ')';
    return text.str();
}

/// `csgrt info --json`: what the text report says, as one JSON object (docs/rendering.md).
void print_info_json(const std::string& scene_path, const Scene& scene,
                     const std::map<std::string, std::uint64_t>& counts, std::uint64_t shapes,
                     std::size_t unbounded, std::uint64_t triangles, std::ostream& out) {
    std::size_t point_lights = 0;
    for (const Light& light : scene.lights())
        point_lights += std::holds_alternative<PointLight>(light);
    const Camera& camera = scene.camera();
    const bool pinhole = camera.projection == Camera::Projection::Pinhole;
    nlohmann::json camera_json = {{"projection", pinhole ? "pinhole" : "orthographic"},
                                  {"position", json_of(camera.position)},
                                  {"look_at", json_of(camera.look_at)}};
    if (pinhole) {
        camera_json["vertical_fov_degrees"] = camera.vertical_fov_degrees;
    } else {
        camera_json["orthographic_height"] = camera.orthographic_height;
    }
    const Aabb& bounds = scene.bounds();
    const nlohmann::json info = {
        {"scene", scene_path},
        {"objects",
         {{"top_level", scene.objects().size()}, {"unbounded", unbounded}, {"shapes", shapes}}},
        {"kinds", counts},
        {"triangles", triangles},
        {"materials", scene.materials().size()},
        {"lights",
         {{"total", scene.lights().size()},
          {"point", point_lights},
          {"directional", scene.lights().size() - point_lights}}},
        {"camera", camera_json},
        {"bounds", bounds.is_empty() ? nlohmann::json(nullptr)
                                     : nlohmann::json{{"lower", json_of(bounds.lower)},
                                                      {"upper", json_of(bounds.upper)}}},
        {"structure",
         {{"name", scene.accelerator_name()}, {"reason", scene.accelerator_reason()}}}};
    out << info.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
}

void info_command(const std::string& scene_path, bool json, CommandLineStreams streams) {
    Scene scene = load_checked(scene_path);
    scene.commit();  // "auto": what a render without --accel would build
    // Memoised per distinct shape: a 2^64-leaf expansion costs what was loaded, not 2^64.
    const SceneShapeCounts counts = count_scene_shapes(scene);
    std::size_t unbounded = 0;
    for (const SceneObject& object : scene.objects()) {
        if (!object.shape->bounds().is_finite()) ++unbounded;
    }
    if (json) {
        print_info_json(scene_path, scene, counts.by_kind, counts.shapes, unbounded,
                        counts.triangles, streams.out);
        return;
    }
    std::ostream& out = streams.out;
    out << "scene:      " << scene_path << '\n';
    out << "objects:    " << scene.objects().size() << " top-level (" << unbounded
        << " unbounded), " << counts.shapes << " shapes in the trees under them (" << counts.leaves
        << " leaves):\n";
    for (const auto& [kind, count] : counts.by_kind) {
        char row[96];
        std::snprintf(row, sizeof(row), "  %-18s %llu", kind.c_str(),
                      static_cast<unsigned long long>(count));
        out << row;
        if (kind == "mesh") out << " (" << counts.triangles << " triangles in all)";
        out << '\n';
    }
    if (const auto meshes = counts.by_kind.find("mesh"); meshes != counts.by_kind.end()) {
        out << "meshes:     " << counts.closed_meshes
            << " closed (solids: CSG operands, inside/outside), "
            << meshes->second - counts.closed_meshes << " open\n";
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

namespace {

// The handler may only call async-signal-safe functions, so everything it needs is prepared
// beforehand in these fixed buffers: the folder, opened, and the name prefixes.
int signal_directory = -1;
char signal_prefixes[3][512];
int signal_prefix_count = 0;
struct sigaction previous_interrupt, previous_terminate;

/// Removes the folder's entries that start with one of the prefixes, then dies of the signal
/// as it would have without the handler.
extern "C" void remove_temporaries_and_die(int signal) {
    if (signal_directory >= 0) {
        alignas(8) char buffer[4096];
        ::lseek(signal_directory, 0, SEEK_SET);
        long bytes;
        while ((bytes = ::syscall(SYS_getdents64, signal_directory, buffer, sizeof buffer)) > 0) {
            for (long offset = 0; offset < bytes;) {
                const auto* entry = reinterpret_cast<const struct dirent64*>(buffer + offset);
                for (int p = 0; p < signal_prefix_count; ++p) {
                    if (std::strncmp(entry->d_name, signal_prefixes[p],
                                     std::strlen(signal_prefixes[p])) == 0) {
                        ::unlinkat(signal_directory, entry->d_name, 0);
                    }
                }
                offset += entry->d_reclen;
            }
        }
    }
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

}  // namespace

TemporariesRemovedOnSignal::TemporariesRemovedOnSignal(const std::filesystem::path& exr_path) {
    const fs::path directory =
        exr_path.parent_path().empty() ? fs::path(".") : exr_path.parent_path();
    signal_directory = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    signal_prefix_count = 0;
    // exr.cpp's TemporaryFile names: ".<target name>.tmp-<pid>-<counter>".
    for (const fs::path& target :
         {exr_path, colour_preview_path(exr_path), cost_preview_path(exr_path)}) {
        const std::string prefix =
            "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-";
        if (prefix.size() >= sizeof signal_prefixes[0]) continue;
        std::memcpy(signal_prefixes[signal_prefix_count], prefix.c_str(), prefix.size() + 1);
        ++signal_prefix_count;
    }
    struct sigaction action {};
    action.sa_handler = remove_temporaries_and_die;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, &previous_interrupt);
    ::sigaction(SIGTERM, &action, &previous_terminate);
}

TemporariesRemovedOnSignal::~TemporariesRemovedOnSignal() {
    ::sigaction(SIGINT, &previous_interrupt, nullptr);
    ::sigaction(SIGTERM, &previous_terminate, nullptr);
    if (signal_directory >= 0) ::close(signal_directory);
    signal_directory = -1;
    signal_prefix_count = 0;
}

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
        "when a scene cannot be loaded or a render fails, 2 for a usage error (bad option, "
        "missing file); every error is one line on stderr.\n"
        "\n"
        "Documentation: 'man csgrt', and " CSGRT_DOC_DIR
        " (README.md, rendering.md,\n"
        "scene-format.md, the JSON Schema scene.schema.json, example scenes in examples/).");

    RenderOptions options;
    CLI::App* render = app.add_subcommand("render", "Render a scene to an EXR with PNG previews");
    render->footer(
        "Writes OUT.exr with the channels R G B A (half, linear, premultiplied), Z (distance\n"
        "along the centre camera ray; inf for background), N.X N.Y N.Z (world normal) and cost\n"
        "(structure nodes visited plus primitives tested) in its part \"rgba\", and id (uint\n"
        "object index; 4294967295 for background, named by the idManifest) in its part \"id\";\n"
        "beside it OUT.png (colour, tone mapped by --tonemap, sRGB) and OUT.cost.png (cost in\n"
        "false colour, with a scale). Prints one summary line: time, Mrays/s, the structure (with\n"
        "--json, one JSON object instead); --stats adds a table of rays, hits, the structure's work and time per stage.");
    render->add_option("scene", options.scene, "The JSON scene file")
        ->required()
        ->check(CLI::ExistingFile)
        ->type_name("SCENE.json");
    render->add_option("-o,--output", options.output, "The EXR file to write")
        ->required()
        ->type_name("OUT.exr");
    render->add_option("--width", options.width, "Image width in pixels")
        ->check(CLI::Range(1, kMaxImageSize))
        ->capture_default_str();
    render->add_option("--height", options.height, "Image height in pixels")
        ->check(CLI::Range(1, kMaxImageSize))
        ->capture_default_str();
    render
        ->add_option("--spp", options.samples_per_pixel,
                     "Samples per pixel on a stratified jittered grid")
        ->check(CLI::Range(1, kMaxSamplesPerPixel))
        ->capture_default_str();
    render->add_option("--threads", options.threads, "Worker threads; 0 uses every core")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    std::vector<std::string> structures = {"auto"};
    for (std::string_view name : accelerator_names()) structures.emplace_back(name);
    render
        ->add_option("--accel", options.accelerator,
                     "The structure over the scene's objects: " + available_structures() +
                         " ('csgrt info' shows what auto picks)")
        ->check(CLI::IsMember(structures))
        ->capture_default_str()
        ->type_name("NAME");
    render
        ->add_option("--tonemap", options.tone_curve,
                     "The PNG preview's tone curve: filmic (ACES fit), reinhard (x/(1+x)) or "
                     "clamp; the EXR stays linear")
        ->capture_default_str()
        ->type_name("CURVE");
    render
        ->add_option("--exposure", options.exposure_stops,
                     "Stops of exposure applied before the PNG's tone curve (linear * 2^EV)")
        ->capture_default_str()
        ->type_name("EV");
    render->add_flag("--timing-in-header", options.timing_in_header,
                     "Record acceleratorBuildMs and renderSeconds in the EXR header (files of "
                     "identical renders then differ)");
    render->add_flag("--stats", options.statistics,
                     "Print a statistics table after the summary: rays by kind, hits by shape "
                     "kind, the structure's work, time per stage");
    render->add_flag("--json", options.json, "Print the summary as one JSON object");

    std::string scene_path;
    bool info_json = false;
    CLI::App* info = app.add_subcommand("info", "Describe a scene and the structure 'auto' builds");
    info->footer(
        "Counts every shape by kind through the whole tree (instances, booleans, compounds;\n"
        "a shared shape once per use), and prints materials, lights, camera, world bounds\n"
        "and the structure 'auto' picks for the top-level objects, with the reason.");
    info->add_option("scene", scene_path, "The JSON scene file")
        ->required()
        ->check(CLI::ExistingFile)
        ->type_name("SCENE.json");
    info->add_flag("--json", info_json, "Print the description as one JSON object");
    CLI::App* validate =
        app.add_subcommand("validate", "Check a scene file (errors only; exit 0 when usable)");
    validate->footer(
        "Loads and commits the scene. Prints nothing and exits 0 when it is usable; otherwise\n"
        "prints the first error (file, place in the file, what was expected) and exits 1.");
    validate->add_option("scene", scene_path, "The JSON scene file")
        ->required()
        ->check(CLI::ExistingFile)
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
            info_command(scene_path, info_json, streams);
        } else {
            validate_command(scene_path);
        }
        return 0;
    } catch (const UsageError& error) {
        streams.out.flush();
        streams.err << "csgrt: error: " << one_line(error.what()) << std::endl;
        return kUsageErrorStatus;
    } catch (const std::exception& error) {
        streams.out.flush();
        streams.err << "csgrt: error: " << one_line(error.what()) << std::endl;
        return 1;
    }
}

}  // namespace csgrt
