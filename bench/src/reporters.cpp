// The benchmark's results as they come: the registry of what each benchmark measures, the
// reporters that collect, forward and display the runs, and the machine the run is on.

#include "report.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <limits>
#include <thread>


namespace csgrt::bench {

namespace {

std::map<std::string, BenchmarkInfo>& registry() {
    static std::map<std::string, BenchmarkInfo> infos;
    return infos;
}

}  // namespace

void register_info(const std::string& name, const BenchmarkInfo& info) {
    registry()[name] = info;
}

double Result::counter(const std::string& key) const {
    const auto found = counters.find(key);
    return found == counters.end() ? std::numeric_limits<double>::quiet_NaN() : found->second;
}

std::vector<benchmark::BenchmarkReporter::Run> with_items_per_second(
    const std::vector<benchmark::BenchmarkReporter::Run>& runs) {
    std::vector<benchmark::BenchmarkReporter::Run> converted = runs;
    for (auto& run : converted) {
        const auto rays = run.counters.find("rays");
        if (rays == run.counters.end()) continue;
        run.counters["items_per_second"] =
            benchmark::Counter(rays->second.value, benchmark::Counter::kIsRate);
        run.counters.erase("rays");
    }
    return converted;
}

ThroughputReporter::ThroughputReporter(benchmark::BenchmarkReporter* inner) : inner_(inner) {}

bool ThroughputReporter::ReportContext(const Context& context) {
    // The library points a file reporter at the --benchmark_out file and leaves a display
    // reporter on the standard streams: the inner one writes where this one would.
    inner_->SetOutputStream(&GetOutputStream());
    inner_->SetErrorStream(&GetErrorStream());
    return inner_->ReportContext(context);
}

void ThroughputReporter::ReportRuns(const std::vector<Run>& runs) {
    inner_->ReportRuns(with_items_per_second(runs));
}

void ThroughputReporter::Finalize() {
    inner_->Finalize();
}

CollectingReporter::CollectingReporter(benchmark::BenchmarkReporter* display)
    : ThroughputReporter(display) {}

void CollectingReporter::ReportRuns(const std::vector<Run>& runs) {
    ThroughputReporter::ReportRuns(runs);
    for (const Run& run : runs) {
        // Repetitions: keep the median aggregate if there is one, else the last run.
        const bool aggregate = run.run_type == Run::RT_Aggregate;
        if (aggregate && run.aggregate_name != "median") continue;
        Result result;
        result.name = run.run_name.function_name;
        const auto info = registry().find(result.name);
        if (info != registry().end()) result.info = info->second;
        // Manual time (the CSG frames) is kept where real time is.
        result.real_time = run.run_name.time_type.find("real_time") != std::string::npos ||
                           run.run_name.time_type.find("manual_time") != std::string::npos;
        result.iterations = run.iterations;
        const double iterations = std::max<double>(1.0, static_cast<double>(run.iterations));
        const double accumulated =
            result.real_time ? run.real_accumulated_time : run.cpu_accumulated_time;
        result.seconds = aggregate ? accumulated : accumulated / iterations;
        result.wall_seconds =
            aggregate ? run.real_accumulated_time : run.real_accumulated_time / iterations;
        for (const auto& [key, counter] : run.counters) result.counters[key] = counter.value;
        result.failed = run.error_occurred;
        result.message = run.error_message;
        auto same = std::find_if(results_.begin(), results_.end(),
                                 [&](const Result& r) { return r.name == result.name; });
        if (same != results_.end()) {
            *same = result;
        } else {
            results_.push_back(result);
        }
    }
}

namespace {

class CompactReporter final : public benchmark::BenchmarkReporter {
public:
    bool ReportContext(const Context&) override { return true; }
    void ReportRuns(const std::vector<Run>& runs) override {
        for (const Run& run : runs) {
            if (run.run_type == Run::RT_Aggregate) continue;
            std::ostream& out = GetOutputStream();
            char name[96];
            std::snprintf(name, sizeof name, "  %-48s", run.run_name.function_name.c_str());
            out << name;
            if (run.error_occurred) {
                out << ": " << run.error_message << "\n";
                continue;
            }
            const auto rays = run.counters.find("items_per_second");
            if (run.run_name.function_name.rfind("csg/", 0) == 0) {
                char text[64];
                std::snprintf(text, sizeof text, " %10.3g ms/frame", run.GetAdjustedRealTime());
                out << text;
            } else if (rays != run.counters.end()) {
                char text[64];
                std::snprintf(text, sizeof text, " %10.3g Mrays/s", rays->second.value * 1e-6);
                out << text;
            }
            out << "\n" << std::flush;
        }
    }
};

}  // namespace

benchmark::BenchmarkReporter* make_compact_reporter() {
    return new CompactReporter();
}

std::string load_average() {
    std::ifstream file("/proc/loadavg");
    double one = 0.0, five = 0.0, fifteen = 0.0;
    if (!(file >> one >> five >> fifteen)) return "unknown";
    char text[64];
    std::snprintf(text, sizeof text, "%.2f, %.2f, %.2f", one, five, fifteen);
    return text;
}

RunContext describe_machine() {
    RunContext context;
    const auto now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm utc{};
    gmtime_r(&now, &utc);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", &utc);
    context.date = date;
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line)) {
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            if (colon != std::string::npos) context.machine = line.substr(colon + 2);
            break;
        }
    }
    if (context.machine.empty()) context.machine = "unknown CPU";
    context.cores = static_cast<int>(std::thread::hardware_concurrency());
    context.load_before = load_average();
    return context;
}

}  // namespace csgrt::bench
