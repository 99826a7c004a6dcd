#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "command_line_internal.h"
#include "csgrt/accel/factory.h"
#include "csgrt/core/error.h"
#include "csgrt/render/cost_layers.h"
#include "csgrt/render/exr.h"
#include "csgrt/render/tonemap.h"

namespace csgrt::command_line {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// Fails unless a file can be made in `directory`, by making one (named as the writer's
/// temporaries, so the signal handler would remove it too) and removing it: permission bits
/// alone do not say, since root passes them all and still cannot write to a read-only
/// filesystem, /sys or /proc.
void require_can_create_files(const fs::path& directory, const fs::path& output) {
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
    std::string name = ".";
    name.append(output.filename().string()).append(".tmp-");
    name.append(std::to_string(::getpid())).append("-probe");
    const fs::path probe = directory / name;
    const int file = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (file < 0) {
        // A file of that name is there already: the folder takes files.
        if (errno == EEXIST) return;
        throw UsageError("output directory '" + directory.string() +
                         "' is not writable: " + std::strerror(errno));
    }
    ::close(file);
    ::unlink(probe.c_str());
}

/// Fails early, before any work, for an output the writer could not produce or that would
/// replace the scene it renders.
void check_output_path(const fs::path& path, const fs::path& scene, bool with_cost_sheet) {
    if (path.extension() != ".exr") {
        throw UsageError("output '" + path.string() +
                         "' must end in .exr (the PNG previews are written beside it)");
    }
    const fs::path directory = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code error;
    const fs::file_status status = fs::status(directory, error);
    if (error == std::errc::not_a_directory) {
        throw UsageError("output directory '" + directory.string() +
                         "' is not a directory: a folder on its path is a file");
    }
    if (!fs::exists(status)) {
        throw UsageError("output directory '" + directory.string() + "' does not exist");
    }
    if (!fs::is_directory(status)) {
        throw UsageError("output directory '" + directory.string() + "' is not a directory");
    }
    require_can_create_files(directory, path);
    for (const fs::path& target : render_file_paths(path, with_cost_sheet)) {
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
/// previews' 8-bit rows and the EXR's half colour; with `cost_layers`, their four floats a
/// pixel each and the contact sheet's row of tiles.
std::uint64_t image_bytes(int width, int height, std::size_t cost_layers) {
    const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
    return pixels * (sizeof(Pixel) + 4 + 4 + 8 + cost_layers * (4 * sizeof(float) + 3));
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

    /// Clears the bar's line, if one was drawn; returns whether one was.
    bool finish() {
        std::lock_guard lock(mutex_);
        const bool drawn = drawn_;
        if (drawn_) err_ << '\r' << std::string(kWidth + 40, ' ') << '\r' << std::flush;
        drawn_ = false;
        return drawn;
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

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

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
    check_output_path(output, options.scene, options.cost_all);
    const std::uint64_t needed = image_bytes(options.width, options.height,
                                             options.cost_all ? accelerator_names().size() : 0);
    const std::uint64_t available = memory_available(streams.memory_bytes);
    if (needed > available) {
        throw UsageError("a " + std::to_string(options.width) + "x" +
                         std::to_string(options.height) + " image needs about " +
                         in_mebibytes(needed) + ", more than the " + in_mebibytes(available) +
                         " of memory free here; render a smaller image");
    }

    StageSeconds stage_seconds;
    Clock::time_point stage_start = Clock::now();
    Scene scene = load_checked(options.scene);
    stage_seconds.emplace_back("load scene", seconds_since(stage_start));
    stage_start = Clock::now();
    SceneConfig config;
    config.accelerator = options.accelerator;
    scene.commit(config);
    stage_seconds.emplace_back("commit (build structures)", seconds_since(stage_start));

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
    stage_seconds.emplace_back("render", result.stats.seconds);

    // --cost-all: the scene rebuilt with each registered structure at every level, its centre
    // rays counted (docs/rendering.md).
    // A line per structure on stderr as it goes: brute force on a big mesh takes a while.
    std::vector<CostLayer> layers;
    if (options.cost_all) {
        stage_start = Clock::now();
        RenderSettings cost_settings = settings;
        const std::span<const std::string_view> names = accelerator_names();
        for (std::size_t i = 0; i < names.size(); ++i) {
            const std::string line = "cost of every structure: " + std::string(names[i]) + " (" +
                                     std::to_string(i + 1) + " of " + std::to_string(names.size()) +
                                     ") ...";
            streams.err << line << std::flush;
            // On a terminal a long trace also draws the bar, over the line, which is then
            // written again.
            ProgressBar structure_bar(streams.err, streams.err_is_terminal,
                                      streams.progress_delay_seconds);
            cost_settings.progress = [&structure_bar](double fraction) {
                structure_bar.update(fraction);
            };
            layers.push_back(cost_layer(scene, cost_settings, names[i]));
            const bool redraw = structure_bar.finish();
            char done[96];
            std::snprintf(done, sizeof(done), " built in %.3f ms, traced in %.3f s\n",
                          layers.back().build_milliseconds,
                          layers.back().trace_milliseconds / 1000.0);
            streams.err << (redraw ? line : std::string()) << done << std::flush;
        }
        stage_seconds.emplace_back("cost of every structure", seconds_since(stage_start));
    }

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
        write_render_files(output, result.image, metadata, tone_mapping, layers);
    }
    stage_seconds.emplace_back("write files", seconds_since(stage_start));
    const std::vector<fs::path> outputs = render_file_paths(output, !layers.empty());

    if (options.json) {
        nlohmann::json summary = {
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
            {"outputs", nlohmann::json::array()}};
        for (const fs::path& path : outputs) summary["outputs"].push_back(path.string());
        if (!layers.empty()) {
            summary["cost_layers"] = nlohmann::json::array();
            for (const CostLayer& layer : layers) {
                summary["cost_layers"].push_back({{"structure", layer.structure},
                                                  {"build_milliseconds", layer.build_milliseconds},
                                                  {"trace_milliseconds", layer.trace_milliseconds},
                                                  {"total", cost_sum(layer)}});
            }
        }
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
    summary << structure.build_milliseconds << " ms; wrote ";
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        summary << (i > 0 ? ", " : "") << outputs[i].string();
    }
    streams.out << summary.str() << '\n';
    if (options.statistics) {
        print_statistics(streams.out, scene, result.stats, stage_seconds, layers);
    }
}

}  // namespace csgrt::command_line
