#pragma once

#include <string>
#include <string_view>

#include "csgrt/csg/scene_file.h"

namespace csgrt::test {

/// The message of the SceneError that loading the scene text `text` (named "test.json")
/// throws, or "no error" when it loads: what the scene-file tests compare against the
/// messages a user would read.
inline std::string scene_error_of(std::string_view text) {
    try {
        load_scene_from_string(text, "test.json");
    } catch (const SceneError& error) {
        return error.what();
    }
    return "no error";
}

}  // namespace csgrt::test
