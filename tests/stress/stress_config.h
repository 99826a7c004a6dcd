#pragma once

#include <cstdlib>
#include <string>

namespace csgrt::test {

/// The stress suite's size: 1 normally (the whole folder runs in about a minute in Release),
/// larger when CSGRT_STRESS_LONG is set (to 1: 10 times the rays; to n > 1: n times), for
/// local runs before a release.
inline int stress_multiplier() {
    const char* value = std::getenv("CSGRT_STRESS_LONG");
    if (!value || !*value) return 1;
    const int n = std::atoi(value);
    return n > 1 ? n : 10;
}

/// Whether CSGRT_STRESS_VERBOSE is set: tables then have a row per case, not per shape.
inline bool stress_verbose() {
    const char* value = std::getenv("CSGRT_STRESS_VERBOSE");
    return value && *value && std::string(value) != "0";
}

}  // namespace csgrt::test
