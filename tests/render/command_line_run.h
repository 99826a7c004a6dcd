#pragma once

// What the command-line suites share: one run of the csgrt program, in this process, and the
// scene they run it on.

#include <sstream>
#include <string>
#include <vector>

#include "csgrt/render/command_line.h"

namespace csgrt::test {

/// The exit status and the output of one run of the program.
struct ProgramRun {
    int status;
    std::string out;
    std::string err;
};

/// Runs `csgrt arguments...` through run_csgrt, its streams captured.
inline ProgramRun run_program(std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), "csgrt");
    std::vector<const char*> argv;
    for (const std::string& argument : arguments) argv.push_back(argument.c_str());
    std::ostringstream out, err;
    const int status =
        run_csgrt(static_cast<int>(argv.size()), argv.data(), CommandLineStreams{out, err});
    return {status, out.str(), err.str()};
}

/// A plane, a box minus a sphere, and a union of an instanced sphere and a sphere: 8 shapes
/// counted by hand, 3 top-level objects of which the plane is unbounded, 2 lights.
inline constexpr const char* kCommandLineScene = R"({
  "camera": {"position": [0, 2, 6], "look_at": [0, 0.5, 0]},
  "materials": {"red": {"albedo": [0.8, 0.2, 0.2]}},
  "lights": [{"type": "point", "position": [3, 5, 4], "intensity": [120, 120, 120]},
             {"type": "directional", "direction": [0, -1, 0]}],
  "objects": [
    {"type": "plane", "normal": [0, 1, 0]},
    {"type": "difference", "material": "red", "operands": [
        {"type": "box", "lower": [-1, 0, -1], "upper": [1, 2, 1]},
        {"type": "sphere", "center": [0, 2, 0], "radius": 1.2}]},
    {"type": "union", "operands": [
        {"type": "sphere", "radius": 0.4, "transform": [{"translate": [2, 0.4, 0]}]},
        {"type": "sphere", "center": [2, 0.9, 0], "radius": 0.3}]}
  ]
})";

}  // namespace csgrt::test
