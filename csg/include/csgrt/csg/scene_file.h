#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
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

/// The shapes in the trees under a scene's objects as a render meets them: every grid copy
/// and every use of a shared definition counts. Computed once per distinct shape in memory
/// (memoised), so it costs time linear in what was loaded, not in the expansion, which a
/// file may make 2^64 leaves large (the loader refuses more than docs/scene-format.md's
/// limit). Counts saturate at 2^64 - 1.
struct SceneShapeCounts {
    /// Shapes of each kind() ("sphere", "instance", "union", ...).
    std::map<std::string, std::uint64_t> by_kind;
    /// Every node: the sum of by_kind.
    std::uint64_t shapes = 0;
    /// Shapes with no children() (what a ray can finally be tested against).
    std::uint64_t leaves = 0;
    /// Triangles of the meshes, each mesh once per use.
    std::uint64_t triangles = 0;
    /// Meshes (counted as in by_kind) that are closed: solids, usable as CSG operands.
    std::uint64_t closed_meshes = 0;
};

/// Counts `scene`'s shapes (`csgrt info`).
SceneShapeCounts count_scene_shapes(const Scene& scene);

/// Every value the "type" of a scene-file shape may have, in the order the format lists them.
std::span<const std::string_view> scene_shape_types();

}  // namespace csgrt
