#pragma once

// What the terminal summaries (summary.cpp) and the report files (report.cpp) share: reading a
// result by its meaning, and formatting numbers and columns. Private to bench/src.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "report.h"

namespace csgrt::bench {

/// A number with about three significant digits.
inline std::string format_number(double value) {
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

inline std::string format_ratio(double value) {
    return std::isfinite(value) ? format_number(value) + "x" : "–";
}

inline const Result* find_result(const std::vector<Result>& results, const std::string& section,
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
inline double trace_rate(const std::vector<Result>& results, const std::string& mesh,
                         const std::string& variant, const std::string& rays, int threads) {
    const Result* result = find_result(results, "trace", mesh, variant, rays, threads);
    return result != nullptr ? result->counter("rays") : std::numeric_limits<double>::quiet_NaN();
}

/// The variants traced on `mesh`, in the order they ran, optionally without the double ones.
inline std::vector<std::string> traced_variants(const std::vector<Result>& results,
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

inline std::string pad(const std::string& text, std::size_t width) {
    // Count UTF-8 code points, so the dash of a missing value pads like one character.
    std::size_t length = 0;
    for (unsigned char c : text) length += (c & 0xc0) != 0x80 ? 1 : 0;
    return length >= width ? text : std::string(width - length, ' ') + text;
}

}  // namespace csgrt::bench
