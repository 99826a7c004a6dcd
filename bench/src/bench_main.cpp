// csgrt_bench: how much each acceleration structure speeds up ray-mesh intersection, against
// brute force, CGAL's AABB tree and Embree measured in the same run; how build and query time
// scale from 10^3 to 10^7 triangles; what each faster variant gives up in accuracy; the time
// per frame of the CSG scenes with and without hierarchical bounding boxes. A Google Benchmark
// program: the standard flags work
// (--benchmark_filter, --benchmark_format=json, --benchmark_out=...), plus the options below.
#include <benchmark/benchmark.h>

#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "benchmarks.h"
#include "csgrt/accel/factory.h"
#include "peers.h"
#include "report.h"

namespace {

using csgrt::bench::Settings;

constexpr const char* kUsage = R"(csgrt_bench [--quick | --full] [options] [Google Benchmark flags]

  --quick          armadillo only, camera (128x128) and incoherent (16384) rays, one thread,
                   CSG scenes at 128x128: the summary tables, in well under two minutes
  (default)        real meshes, generated meshes up to 3.3M triangles, 512x512 camera rays,
                   threads, builds, scaling, accuracy, CSG scenes
  --full           every real mesh, generated meshes up to 13.3M triangles, 1024x1024
  --report DIR     also write DIR/report.md and DIR/report.json (plots: scripts/plot_benchmarks.py)
  --commit HASH    the commit named in the report
  --threads N      the "all threads" count, 1..1024 (default: the hardware threads)
  --data DIR       the repository's data/ folder (default: the first data/ holding scenes/
                   in the folders above this program, so a build tree inside the source
                   tree finds it)

--quick and --full exclude each other. --benchmark_list_tests prints only the benchmarks'
names. Ray throughput is Google Benchmark's items_per_second (rays per second).
)";

constexpr int kMaxThreads = 1024;

/// The data/ folder of the repository this program was built in: the first folder called
/// data with a scenes/ inside, in the program's folder or one above it. Empty when none is.
std::filesystem::path find_data_folder() {
    std::error_code error;
    const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
    if (error) return {};
    for (std::filesystem::path folder = program.parent_path(); !folder.empty();
         folder = folder.parent_path()) {
        if (std::filesystem::is_directory(folder / "data" / "scenes", error)) {
            return folder / "data";
        }
        if (folder == folder.parent_path()) break;
    }
    return {};
}

/// --threads' value: a whole number in [1, kMaxThreads], or an error saying so.
int parse_threads(const std::string& text) {
    int threads = 0;
    const char* end = text.data() + text.size();
    const auto [last, status] = std::from_chars(text.data(), end, threads);
    if (text.empty() || status != std::errc() || last != end || threads < 1 ||
        threads > kMaxThreads) {
        throw std::invalid_argument("--threads wants a whole number from 1 to " +
                                    std::to_string(kMaxThreads) + ", got '" + text + "'");
    }
    return threads;
}

struct Options {
    Settings settings;
    std::filesystem::path report;
    std::string commit = "unknown";
    bool help = false;
};

/// Takes csgrt_bench's own options out of argv, leaving Google Benchmark's flags.
Options parse_options(int& argc, char** argv) {
    Options options;
    options.settings.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    std::string mode = "standard";
    bool data_given = false;
    int kept = 1;
    for (int i = 1; i < argc; ++i) {
        const std::string argument = argv[i];
        auto value = [&](const std::string& flag) -> std::string {
            if (argument.rfind(flag + "=", 0) == 0) return argument.substr(flag.size() + 1);
            if (i + 1 < argc) return argv[++i];
            throw std::invalid_argument(flag + " needs a value");
        };
        auto is = [&](const std::string& flag) {
            return argument == flag || argument.rfind(flag + "=", 0) == 0;
        };
        if (argument == "--quick" || argument == "--full") {
            const std::string chosen = argument.substr(2);
            if (mode != "standard" && mode != chosen) {
                throw std::invalid_argument("--quick and --full exclude each other");
            }
            mode = chosen;
        } else if (argument == "--help" || argument == "-h") {
            options.help = true;
        } else if (is("--report")) {
            options.report = value("--report");
        } else if (is("--commit")) {
            options.commit = value("--commit");
        } else if (is("--threads")) {
            options.settings.threads = parse_threads(value("--threads"));
        } else if (is("--data")) {
            options.settings.data = value("--data");
            data_given = true;
        } else {
            argv[kept++] = argv[i];
        }
    }
    argc = kept;
    if (!data_given) options.settings.data = find_data_folder();
    if (options.settings.data.empty()) {
        throw std::invalid_argument(
            "cannot find the data/ folder above this program; give it with --data DIR");
    }
    if (!std::filesystem::is_directory(options.settings.data)) {
        throw std::invalid_argument("--data " + options.settings.data.string() + ": not a folder");
    }
    Settings& settings = options.settings;
    settings.mode = mode;
    if (mode == "quick") {
        settings.sizes = {128, 16384};
        settings.brute_budget = 2e7;
        settings.csg_width = 128;
    } else if (mode == "full") {
        settings.sizes = {1024, 1048576};
        settings.brute_budget = 3e8;
        settings.accuracy_width = 512;
        settings.accuracy_rays = 16384;
    } else {
        settings.sizes = {512, 262144};
        settings.brute_budget = 1e8;
    }
    return options;
}

bool has_flag(int argc, char** argv, const char* prefix) {
    for (int i = 1; i < argc; ++i) {
        if (std::strncmp(argv[i], prefix, std::strlen(prefix)) == 0) return true;
    }
    return false;
}

/// Registers everything the mode measures, mesh by mesh.
void register_all(csgrt::bench::Workloads& workloads, const Settings& settings) {
    using namespace csgrt::bench;
    const std::filesystem::path meshes = settings.data / "meshes";
    const std::filesystem::path generated = settings.data / "generated";
    std::vector<std::string> real = {"armadillo"};
    std::vector<std::size_t> sizes;
    if (settings.mode == "standard") {
        real = {"armadillo", "bunny00", "ChineseDragon-10kv"};
        sizes = {1000, 10000, 208000, 832000, 3328000};
    } else if (settings.mode == "full") {
        real = {"armadillo", "bunny00", "ChineseDragon-10kv", "elephant", "refined_elephant",
                "cow",       "fandisk"};
        sizes = {1000, 10000, 208000, 832000, 3328000, 13312000};
    }
    const bool quick = settings.mode == "quick";
    const int all = settings.threads;
    for (const std::string& mesh : real) {
        const std::filesystem::path path = meshes / (mesh + ".off");
        if (!std::filesystem::exists(path)) {
            std::fprintf(stderr, "csgrt_bench: %s is missing (run data/fetch-meshes); skipped\n",
                         path.c_str());
            continue;
        }
        workloads.add(mesh, path);
        const std::vector<std::string> ray_sets =
            quick ? std::vector<std::string>{"camera", "incoherent"}
                  : std::vector<std::string>{"camera", "incoherent", "shadow"};
        for (const Variant& variant : mesh_variants(!quick, !quick)) {
            for (const std::string& rays : ray_sets) {
                register_trace(workloads, settings, mesh, variant, rays, 1);
            }
        }
        for (const std::string& rays : ray_sets) {
            register_batch_trace(workloads, mesh, rays, 1);
            if (!quick) register_user_loop_trace(workloads, mesh, rays);
            if (all > 1 && !quick) register_batch_trace(workloads, mesh, rays, all);
        }
        if (quick) continue;
        for (const Variant& variant : mesh_variants(false, false)) {
            if (variant.is_brute() || all <= 1) continue;
            for (const std::string& rays : ray_sets) {
                register_trace(workloads, settings, mesh, variant, rays, all);
            }
        }
        for (const Variant& variant : mesh_variants(false, false)) {
            if (variant.is_brute()) continue;
            register_build(workloads, mesh, variant, 1);
            if (all > 1) register_build(workloads, mesh, variant, all);
        }
    }
    for (std::size_t triangles : sizes) {
        const std::string mesh = "armadillo-" + std::to_string(triangles);
        const std::filesystem::path path = generated / (mesh + ".ply");
        if (!std::filesystem::exists(path)) {
            std::fprintf(stderr,
                         "csgrt_bench: %s is missing (run data/generate-meshes%s); skipped\n",
                         path.c_str(), triangles > 4000000 ? " --huge" : "");
            continue;
        }
        workloads.add(mesh, path);
        for (const Variant& variant : mesh_variants(false, false)) {
            if (variant.kind == Variant::Kind::kStructure && variant.box_culling) continue;
            for (const std::string rays : {"camera", "incoherent"}) {
                register_trace(workloads, settings, mesh, variant, rays, 1);
            }
            if (variant.is_brute()) continue;
            register_build(workloads, mesh, variant, 1);
            // The BVH's build floor (3.3M triangles in under 1 s) is for every thread.
            if (all > 1) register_build(workloads, mesh, variant, all);
        }
    }
    register_csg_benchmarks(settings);
    if (quick) return;
    register_accuracy_benchmarks(workloads, settings);
}

}  // namespace

int main(int argc, char** argv) {
    Options options;
    try {
        options = parse_options(argc, argv);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "csgrt_bench: %s\n%s", error.what(), kUsage);
        return 2;
    }
    if (options.help) {
        std::printf("%s\nGoogle Benchmark flags:\n", kUsage);
        benchmark::PrintDefaultHelp();
        return 0;
    }
    const Settings& settings = options.settings;
    // The mode's default minimum time per benchmark, unless the command line sets one.
    std::vector<char*> arguments(argv, argv + argc);
    std::string min_time = "--benchmark_min_time=";
    min_time += settings.mode == "quick" ? "0.05" : settings.mode == "full" ? "0.5" : "0.2";
    if (!has_flag(argc, argv, "--benchmark_min_time")) arguments.push_back(min_time.data());
    // Initialize removes the flags it knows, so what the output format is must be read first.
    const bool format_given = has_flag(argc, argv, "--benchmark_format");
    // --benchmark_list_tests: the names and nothing else on stdout.
    const bool list_only = has_flag(argc, argv, "--benchmark_list_tests") &&
                           !has_flag(argc, argv, "--benchmark_list_tests=false") &&
                           !has_flag(argc, argv, "--benchmark_list_tests=0");
    // --benchmark_out's reporter, made here so it too reports items_per_second; the library
    // opens the file and points the reporter at it.
    std::string out_format = "json";
    for (int i = 1; i < argc; ++i) {
        const char* flag = "--benchmark_out_format=";
        if (std::strncmp(argv[i], flag, std::strlen(flag)) == 0)
            out_format = argv[i] + std::strlen(flag);
    }
    const bool machine_readable = has_flag(argc, argv, "--benchmark_format=json") ||
                                  has_flag(argc, argv, "--benchmark_format=csv");
    int count = static_cast<int>(arguments.size());
    arguments.push_back(nullptr);
    benchmark::Initialize(&count, arguments.data());
    if (benchmark::ReportUnrecognizedArguments(count, arguments.data())) return 2;

    csgrt::bench::RunContext context = csgrt::bench::describe_machine();
    context.commit = options.commit;
    context.mode = settings.mode;
    context.threads = settings.threads;
    context.embree = csgrt::bench::embree_version();
    context.settings = "camera " + std::to_string(settings.sizes.camera_width) + "x" +
                       std::to_string(settings.sizes.camera_width) + ", " +
                       std::to_string(settings.sizes.incoherent) +
                       " incoherent rays, shadow "
                       "rays from the camera hits, brute force " +
                       std::to_string(static_cast<long long>(settings.brute_budget)) +
                       " triangle tests a pass";
    benchmark::AddCustomContext("csgrt_mode", settings.mode);
    benchmark::AddCustomContext("csgrt_commit", options.commit);
    benchmark::AddCustomContext("csgrt_embree", context.embree);

    csgrt::bench::Workloads workloads(settings.sizes);
    register_all(workloads, settings);

    if (list_only) {
        benchmark::RunSpecifiedBenchmarks();
        benchmark::Shutdown();
        return 0;
    }
    const bool compact = settings.mode == "quick" && !format_given;
    csgrt::bench::CollectingReporter reporter(compact ? csgrt::bench::make_compact_reporter()
                                                      : benchmark::CreateDefaultDisplayReporter());
    if (compact) {
        std::printf("csgrt_bench --quick on %s (%d hardware threads), load average %s\n",
                    context.machine.c_str(), context.cores, context.load_before.c_str());
    }
    std::unique_ptr<benchmark::BenchmarkReporter> file_reporter;
    // (The deprecated CSV format is left to the library's own reporter.)
    if (has_flag(argc, argv, "--benchmark_out=") && out_format != "csv") {
        benchmark::BenchmarkReporter* inner =
            out_format == "console"
                ? static_cast<benchmark::BenchmarkReporter*>(
                      new benchmark::ConsoleReporter(benchmark::ConsoleReporter::OO_None))
                : new benchmark::JSONReporter();
        file_reporter = std::make_unique<csgrt::bench::ThroughputReporter>(inner);
    }
    benchmark::RunSpecifiedBenchmarks(&reporter, file_reporter.get());
    benchmark::Shutdown();
    context.load_after = csgrt::bench::load_average();

    // The summary goes where it does not spoil machine-readable output.
    std::FILE* out = machine_readable ? stderr : stdout;
    const auto& sizes = settings.sizes;
    std::fprintf(out,
                 "\ncsgrt_bench summary: armadillo, %dx%d camera rays and %zu incoherent rays, "
                 "1 thread (CPU time),\nbrute force on an evenly spread subset; peers measured "
                 "in this run: CGAL 5.5 AABB tree, %s.\n",
                 sizes.camera_width, sizes.camera_width, sizes.incoherent, context.embree.c_str());
    std::fprintf(out, "%s", csgrt::bench::summary_table(reporter.results(), "armadillo").c_str());
    const std::string csg = csgrt::bench::csg_summary_table(reporter.results(), 1);
    if (!csg.empty()) {
        std::fprintf(out,
                     "\nCSG scenes of data/scenes, %dx%d with shadows, 1 thread (process CPU "
                     "time); brute = no hierarchical\nbounding boxes (* timed on a smaller frame "
                     "of the same view, scaled by the pixels); per camera ray:\nthe top-level "
                     "structure's object and box tests.\n",
                     settings.csg_width, settings.csg_width);
        std::fprintf(out, "%s", csg.c_str());
    }
    std::fprintf(out, "load average before %s, after %s\n", context.load_before.c_str(),
                 context.load_after.c_str());
    if (!options.report.empty()) {
        csgrt::bench::write_report(options.report, reporter.results(), context);
        std::fprintf(out, "report: %s\n", (options.report / "report.md").c_str());
    }
    return 0;
}
