// csgrt_generate_meshes: makes the benchmark's meshes of about 10^3 to 10^7 triangles from a
// real mesh (the armadillo's 52,000 by default): decimated to 1,000 and 10,000 triangles, Loop
// subdivided once (208,000), twice (832,000), three times (3.3M) and, with --huge, four times
// (13.3M). Each is cached as binary PLY and made only when missing; `data/generate-meshes`
// runs this with the repository's folders.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "csgrt/mesh/mesh_io.h"
#include "csgrt/mesh/mesh_tools.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Options {
    std::filesystem::path meshes = "data/meshes";
    std::filesystem::path output = "data/generated";
    std::string source = "armadillo";
    bool huge = false;
    bool force = false;
};

/// Prints one line of the table: the file, its triangles, and what it cost.
void print_row(const std::filesystem::path& path, std::size_t triangles, const char* status,
               double seconds) {
    std::printf("  %-28s %10zu triangles  %-9s %7.2f s\n", path.filename().c_str(), triangles,
                status, seconds);
    std::fflush(stdout);
}

int run(const Options& options) {
    const auto start = Clock::now();
    const std::filesystem::path source_path = options.meshes / (options.source + ".off");
    if (!std::filesystem::exists(source_path)) {
        std::fprintf(stderr, "csgrt_generate_meshes: %s is missing (run data/fetch-meshes)\n",
                     source_path.c_str());
        return 1;
    }
    std::filesystem::create_directories(options.output);
    csgrt::MeshReport report;
    const csgrt::TriangleMeshData base = csgrt::load_mesh(source_path, &report);
    const std::size_t base_triangles = base.triangles.size();
    std::printf("csgrt_generate_meshes: %s (%s) -> %s\n", options.source.c_str(),
                csgrt::describe(report).c_str(), options.output.c_str());
    auto path_for = [&](std::size_t triangles) {
        return options.output / (options.source + "-" + std::to_string(triangles) + ".ply");
    };

    for (const std::size_t target : {std::size_t{1000}, std::size_t{10000}}) {
        if (target >= base_triangles) continue;
        const std::filesystem::path path = path_for(target);
        if (std::filesystem::exists(path) && !options.force) {
            print_row(path, target, "cached", 0.0);
            continue;
        }
        const auto begin = Clock::now();
        const csgrt::TriangleMeshData coarse = csgrt::decimate(base, target);
        csgrt::save_mesh(path, coarse);
        print_row(path, coarse.triangles.size(), "decimated", seconds_since(begin));
    }

    // Each level is made from the previous one, read back from the cache when only it exists.
    const int levels = options.huge ? 4 : 3;
    std::optional<csgrt::TriangleMeshData> previous = base;
    for (int level = 1; level <= levels; ++level) {
        const std::size_t triangles = base_triangles << (2 * level);
        const std::filesystem::path path = path_for(triangles);
        if (std::filesystem::exists(path) && !options.force) {
            print_row(path, triangles, "cached", 0.0);
            previous.reset();
            continue;
        }
        const auto begin = Clock::now();
        if (!previous) previous = csgrt::load_mesh(path_for(triangles / 4));
        previous = csgrt::loop_subdivide(*previous, 1);
        csgrt::save_mesh(path, *previous);
        print_row(path, previous->triangles.size(), "subdivided", seconds_since(begin));
    }
    std::printf("  total %.2f s\n", seconds_since(start));
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Options options;
    CLI::App app{
        "Makes meshes of about 10^3 to 10^7 triangles from a real mesh, cached as binary PLY."};
    app.add_option("--meshes", options.meshes, "folder of the real meshes (data/fetch-meshes)");
    app.add_option("--output", options.output, "folder of the generated meshes");
    app.add_option("--source", options.source, "the real mesh to start from (an .off name)");
    app.add_flag("--huge", options.huge, "also make the 4-level subdivision (13.3M triangles)");
    app.add_flag("--force", options.force, "remake meshes that are already cached");
    CLI11_PARSE(app, argc, argv);
    try {
        return run(options);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "csgrt_generate_meshes: %s\n", error.what());
        return 1;
    }
}
