#pragma once

#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "csgrt/csg/scene.h"

namespace csgrt {

/// Thrown for a scene file that cannot be used. The message names the file, the place in it
/// (a JSON pointer such as `/objects/3/radius`, or a line and column for invalid JSON) and
/// what was expected: "room.json: /objects/3/radius: Sphere: radius must be > 0 and finite,
/// got -1".
class SceneError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Reads a JSON scene file (docs/scene-format.md): camera, materials, lights, named
/// definitions and objects. Mesh paths are relative to the file's folder. The scene is
/// returned uncommitted, so the caller picks the SceneConfig. Throws SceneError for anything
/// the format does not allow: invalid JSON, duplicate or unknown keys, wrong types, missing
/// fields, invalid parameters, non-solid boolean operands, reference cycles, unusable meshes.
Scene load_scene(const std::filesystem::path& path);

/// The same, from `text`; `name` stands for the file in messages, and mesh paths are relative
/// to `directory`.
Scene load_scene_from_string(std::string_view text, const std::string& name,
                             const std::filesystem::path& directory = {});

/// Every value the "type" of a scene-file shape may have, in the order the format lists them.
std::span<const std::string_view> scene_shape_types();

}  // namespace csgrt
