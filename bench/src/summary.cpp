// The short tables --quick prints on the terminal (summary_table, csg_summary_table).

#include <sstream>
#include <string>
#include <vector>

#include "report.h"
#include "report_format.h"

namespace csgrt::bench {

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

std::string csg_summary_table(const std::vector<Result>& results, int threads) {
    std::ostringstream out;
    for (const Result& result : results) {
        const BenchmarkInfo& info = result.info;
        if (info.section != "csg" || info.threads != threads) continue;
        if (out.tellp() == 0) {
            out << pad("scene", 16) << pad("structure", 11) << pad("objects", 9)
                << pad("ms/frame", 10) << pad("x brute", 9) << pad("objects/ray", 13)
                << pad("boxes/ray", 11) << "\n";
        }
        if (result.failed) {
            out << pad(info.subject, 16) << pad(info.variant, 11) << "  failed: " << result.message
                << "\n";
            continue;
        }
        const Result* brute = find_result(results, "csg", info.subject, "brute", "frame", 1);
        const double flat =
            brute != nullptr ? brute->seconds : std::numeric_limits<double>::quiet_NaN();
        std::string frame = format_number(result.seconds * 1e3);
        if (result.counter("rendered_width") != result.counter("frame_width")) {
            frame += "*";
        }
        out << pad(info.subject, 16) << pad(info.variant, 11)
            << pad(std::to_string(std::llround(result.counter("objects"))), 9) << pad(frame, 10)
            << pad(format_ratio(flat / result.seconds), 9)
            << pad(format_number(result.counter("objects_per_ray")), 13)
            << pad(format_number(result.counter("boxes_per_ray")), 11) << "\n";
    }
    return out.str();
}

}  // namespace csgrt::bench
