#pragma once

// Scene files written in code, for the scene-file suites that need more shapes than a fixture
// would hold.

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

namespace csgrt::test {

/// The text of a scene with definitions d0 (a unit sphere) and d_k = compound [d_{k-1},
/// d_{k-1}] for k up to `levels`, and one object, a ref to d_`levels`: it expands to 2^levels
/// spheres in about 60 bytes a level. With `offset`, the second copy of d_{k-1} is moved along
/// x by it, times 2^(k-1) when `growing` (then no two copies share a place).
inline std::string doubling_scene(int levels, std::optional<double> offset = {},
                                  bool growing = false) {
    std::string text = R"({"definitions": {"d0": {"type": "sphere", "radius": 1})";
    for (int k = 1; k <= levels; ++k) {
        // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
        const std::string below = std::string("d").append(std::to_string(k - 1));
        text.append(", \"d").append(std::to_string(k));
        text.append(R"(": {"type": "compound", "children": [{"type": "ref", "definition": ")");
        text.append(below).append(R"("}, {"type": "ref", "definition": ")").append(below);
        if (!offset) {
            text.append(R"("}]})");
            continue;
        }
        char moved[32];
        std::snprintf(moved, sizeof moved, "%.17g", growing ? std::ldexp(*offset, k - 1) : *offset);
        text.append(R"(", "transform": [{"translate": [)").append(moved).append(", 0, 0]}]}]}");
    }
    return text.append(R"(}, "objects": [{"type": "ref", "definition": "d)")
        .append(std::to_string(levels))
        .append("\"}]}");
}

}  // namespace csgrt::test
