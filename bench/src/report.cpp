#include "report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <limits>
#include <mutex>
#include <set>
#include <sstream>
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

CollectingReporter::CollectingReporter(benchmark::BenchmarkReporter* display) : display_(display) {}

bool CollectingReporter::ReportContext(const Context& context) {
    return display_->ReportContext(context);
}

void CollectingReporter::ReportRuns(const std::vector<Run>& runs) {
    display_->ReportRuns(runs);
    for (const Run& run : runs) {
        // Repetitions: keep the median aggregate if there is one, else the last run.
        const bool aggregate = run.run_type == Run::RT_Aggregate;
        if (aggregate && run.aggregate_name != "median") continue;
        Result result;
        result.name = run.run_name.function_name;
        const auto info = registry().find(result.name);
        if (info != registry().end()) result.info = info->second;
        result.real_time = run.run_name.time_type.find("real_time") != std::string::npos;
        result.iterations = run.iterations;
        const double iterations = std::max<double>(1.0, static_cast<double>(run.iterations));
        const double accumulated =
            result.real_time ? run.real_accumulated_time : run.cpu_accumulated_time;
        result.seconds = aggregate ? accumulated : accumulated / iterations;
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

void CollectingReporter::Finalize() {
    display_->Finalize();
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

namespace {

/// A number with about three significant digits.
std::string format_number(double value) {
    if (!std::isfinite(value)) return "–";
    char text[64];
    const double magnitude = std::abs(value);
    if (magnitude >= 100.0 || magnitude == 0.0) {
        std::snprintf(text, sizeof text, "%.0f", value);
    } else if (magnitude >= 10.0) {
        std::snprintf(text, sizeof text, "%.1f", value);
    } else if (magnitude >= 0.01) {
        std::snprintf(text, sizeof text, "%.2f", value);
    } else {
        std::snprintf(text, sizeof text, "%.2g", value);
    }
    return text;
}

std::string format_ratio(double value) {
    return std::isfinite(value) ? format_number(value) + "x" : "–";
}

const Result* find_result(const std::vector<Result>& results, const std::string& section,
                          const std::string& subject, const std::string& variant,
                          const std::string& rays, int threads) {
    for (const Result& result : results) {
        const BenchmarkInfo& info = result.info;
        if (!result.failed && info.section == section && info.subject == subject &&
            info.variant == variant && info.rays == rays && info.threads == threads) {
            return &result;
        }
    }
    return nullptr;
}

/// Rays per second of a trace benchmark, NaN when it did not run.
double trace_rate(const std::vector<Result>& results, const std::string& mesh,
                  const std::string& variant, const std::string& rays, int threads) {
    const Result* result = find_result(results, "trace", mesh, variant, rays, threads);
    return result != nullptr ? result->counter("rays") : std::numeric_limits<double>::quiet_NaN();
}

/// The variants traced on `mesh`, in the order they ran, optionally without the double ones.
std::vector<std::string> traced_variants(const std::vector<Result>& results,
                                         const std::string& mesh, bool with_double) {
    std::vector<std::string> variants;
    for (const Result& result : results) {
        const BenchmarkInfo& info = result.info;
        if (info.section != "trace" || info.subject != mesh) continue;
        if (!with_double && info.variant.ends_with("-double")) continue;
        if (std::find(variants.begin(), variants.end(), info.variant) == variants.end()) {
            variants.push_back(info.variant);
        }
    }
    return variants;
}

std::string pad(const std::string& text, std::size_t width) {
    // Count UTF-8 code points, so the dash of a missing value pads like one character.
    std::size_t length = 0;
    for (unsigned char c : text) length += (c & 0xc0) != 0x80 ? 1 : 0;
    return length >= width ? text : std::string(width - length, ' ') + text;
}

}  // namespace

std::string summary_table(const std::vector<Result>& results, const std::string& mesh) {
    const std::vector<std::string> variants = traced_variants(results, mesh, false);
    if (variants.empty()) return "no trace results for " + mesh + "\n";
    std::ostringstream out;
    const std::vector<std::string> sets = {"camera", "incoherent"};
    out << pad("", 14);
    for (const std::string& set : sets) {
        out << " | " << pad(set, 10) << pad("x brute", 9) << pad("x CGAL", 9) << pad("x Embree", 9);
    }
    out << "\n" << pad("", 14);
    for (std::size_t i = 0; i < sets.size(); ++i) {
        out << " | " << pad("Mrays/s", 10) << pad("", 27);
    }
    out << "\n";
    for (const std::string& variant : variants) {
        out << pad(variant, 14);
        for (const std::string& set : sets) {
            const double rate = trace_rate(results, mesh, variant, set, 1);
            out << " | " << pad(format_number(rate * 1e-6), 10)
                << pad(format_ratio(rate / trace_rate(results, mesh, "brute", set, 1)), 9)
                << pad(format_ratio(rate / trace_rate(results, mesh, "cgal", set, 1)), 9)
                << pad(format_ratio(rate / trace_rate(results, mesh, "embree", set, 1)), 9);
        }
        out << "\n";
    }
    return out.str();
}

void write_report(const std::filesystem::path& directory, const std::vector<Result>& results,
                  const RunContext& context) {
    std::filesystem::create_directories(directory);
    std::ofstream markdown(directory / "report.md");
    markdown << "# csgrt_bench report\n\n";
    markdown << "- date: " << context.date << "\n- machine: " << context.machine << ", "
             << context.cores << " hardware threads\n- commit: " << context.commit
             << "\n- mode: " << context.mode << "\n";
    markdown << "\n```\n" << summary_table(results, "armadillo") << "```\n";
}

}  // namespace csgrt::bench
