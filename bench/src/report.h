#pragma once

#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace csgrt::bench {

/// What a registered benchmark measures, recorded when it is registered so the report reads
/// results by meaning rather than by parsing names.
struct BenchmarkInfo {
    /// "trace", "build", "accuracy" or "csg".
    std::string section;
    /// The mesh or scene.
    std::string subject;
    /// The structure, peer or variant ("bvh", "cgal", "embree", "mt-float", "hierarchy"...).
    std::string variant;
    /// The ray set ("camera", "incoherent", "shadow") or the accuracy group.
    std::string rays;
    int threads = 1;
};

/// Records `info` for the benchmark registered as `name`.
void register_info(const std::string& name, const BenchmarkInfo& info);

/// One finished benchmark: its info, the time of one iteration (CPU time for one thread, wall
/// time for several, as it was measured) and its counters (rates already per second).
struct Result {
    std::string name;
    BenchmarkInfo info;
    double seconds = 0.0;
    /// Wall time of one iteration whatever was measured, so thread scaling compares wall time
    /// with wall time (a loaded machine slows both alike).
    double wall_seconds = 0.0;
    bool real_time = false;
    std::int64_t iterations = 0;
    std::map<std::string, double> counters;
    bool failed = false;
    std::string message;

    /// A counter, or NaN when absent.
    double counter(const std::string& key) const;
};

/// `runs` with each ray rate (the benchmarks' "rays" counter, already per second) reported as
/// Google Benchmark's own throughput field, items_per_second, which tools that read its
/// console and JSON output know. The Results keep the name "rays".
std::vector<benchmark::BenchmarkReporter::Run> with_items_per_second(
    const std::vector<benchmark::BenchmarkReporter::Run>& runs);

/// Forwards everything to `inner` (for --benchmark_out: the file reporter) with the ray rates
/// as items_per_second, in the streams the library gives this reporter.
class ThroughputReporter : public benchmark::BenchmarkReporter {
public:
    explicit ThroughputReporter(benchmark::BenchmarkReporter* inner);

    bool ReportContext(const Context& context) override;
    void ReportRuns(const std::vector<Run>& runs) override;
    void Finalize() override;

private:
    std::unique_ptr<benchmark::BenchmarkReporter> inner_;
};

/// Forwards everything to the reporter chosen by --benchmark_format (so the standard flags
/// keep working), as a ThroughputReporter does, and keeps a Result for each run.
class CollectingReporter final : public ThroughputReporter {
public:
    explicit CollectingReporter(benchmark::BenchmarkReporter* display);

    void ReportRuns(const std::vector<Run>& runs) override;

    const std::vector<Result>& results() const { return results_; }

private:
    std::vector<Result> results_;
};

/// A one-line-per-benchmark display for --quick: the name and its Mrays/s (Google
/// Benchmark's own table, with every counter, is what the other modes show).
benchmark::BenchmarkReporter* make_compact_reporter();

/// Where and how the run happened, for the report's header.
struct RunContext {
    std::string date;
    std::string machine;
    int cores = 0;
    int threads = 1;
    std::string commit;
    std::string mode;
    std::string embree;
    std::string load_before;
    std::string load_after;
    std::string settings;
};

/// Fills date, machine (the CPU model from /proc/cpuinfo), cores and the load average.
RunContext describe_machine();
/// The 1, 5 and 15 minute load averages from /proc/loadavg.
std::string load_average();

/// The short table --quick prints: one row per structure and peer on `mesh`, camera and
/// incoherent rays, one thread: Mrays/s and the speedups over brute force, CGAL and Embree
/// measured in the same run.
std::string summary_table(const std::vector<Result>& results, const std::string& mesh);

/// The CSG scenes' frames at `threads` threads: ms per frame under each structure, the speedup
/// over brute force (no hierarchical bounding boxes), objects and boxes tested per camera ray;
/// a * marks a frame timed at a smaller size and scaled. Empty when no scene ran.
std::string csg_summary_table(const std::vector<Result>& results, int threads);

/// Writes report.md and report.json (the tables the plots are drawn from) into `directory`.
void write_report(const std::filesystem::path& directory, const std::vector<Result>& results,
                  const RunContext& context);

}  // namespace csgrt::bench
