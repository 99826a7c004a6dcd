#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace csgrt::test {

/// The size the heavy tests (ctest label "heavy", tests/CMakeLists.txt) run at under the
/// sanitizers, as a fraction of their full ray, shape and mesh counts. ASan and UBSan look for
/// memory and undefined-behaviour errors, which the same code paths show at any size; the
/// statistics at full size are proven by the optimised build, which runs at scale 1.
inline constexpr double kSanitizedScale = 0.125;

/// The fraction of its full size a heavy test runs at: kSanitizedScale in a sanitizer build
/// (CSGRT_SANITIZED, which tests/CMakeLists.txt defines with CSGRT_SANITIZE), 1 otherwise;
/// CSGRT_TEST_SCALE in the environment (a number in (0, 1]) overrides either, e.g. to run the
/// asan build at full size.
inline double test_scale() {
    static const double scale = [] {
        if (const char* value = std::getenv("CSGRT_TEST_SCALE"); value && *value) {
            const double requested = std::atof(value);
            if (requested > 0.0 && requested <= 1.0) return requested;
        }
#ifdef CSGRT_SANITIZED
        return kSanitizedScale;
#else
        return 1.0;
#endif
    }();
    return scale;
}

/// Whether the heavy tests run below full size (the sanitizer build, or CSGRT_TEST_SCALE < 1).
inline bool reduced_scale() {
    return test_scale() < 1.0;
}

/// `full` (a count of rays, shapes or cases) at test_scale(), rounded up, and never below
/// `minimum`: thresholds derived from a count scale with it through this function.
template <class Count>
Count scaled(Count full, Count minimum = 1) {
    const auto reduced = static_cast<Count>(std::ceil(static_cast<double>(full) * test_scale()));
    return std::min(full, std::max(reduced, minimum));
}

}  // namespace csgrt::test
