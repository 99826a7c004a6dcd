// The entry points of the scene file (docs/scene-format.md): the file checked before it is
// read, then parsed (scene_file/json_tree.cpp) and loaded (scene_file/loader.cpp).

#include "csgrt/csg/scene_file.h"

#include <fstream>
#include <string>

#include "scene_file/limits.h"
#include "scene_file/loader.h"

namespace csgrt {

namespace {

using detail::scene_file::kMaxSceneFileBytes;
using detail::scene_file::shown;
using detail::scene_file::Source;

Scene load(std::string_view text, const Source& source) {
    const detail::scene_file::Json root = detail::scene_file::parse_scene_json(text, source);
    try {
        return detail::scene_file::Loader(root, source).load();
    } catch (const nlohmann::json::exception& error) {
        // Every value is checked before it is converted; this is a guard, not a path.
        throw SceneError(source.name + ": " + error.what());
    }
}

}  // namespace

Scene load_scene(const std::filesystem::path& path) {
    const std::string& native = path.native();
    if (native.find('\0') != std::string::npos) {
        throw SceneError(shown(native) + ": the path contains a NUL byte");
    }
    // Checked before opening: opening a FIFO blocks, and a device never ends.
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (!std::filesystem::exists(status)) {
        throw SceneError(path.string() + ": cannot open the scene file (no such file)");
    }
    if (!std::filesystem::is_regular_file(status)) {
        const char* kind =
            std::filesystem::is_directory(status) ? "a directory"
            : std::filesystem::is_fifo(status)    ? "a FIFO"
            : std::filesystem::is_character_file(status) || std::filesystem::is_block_file(status)
                ? "a device"
                : "a special file";
        throw SceneError(path.string() + ": is " + kind + ", not a regular file");
    }
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (error) throw SceneError(path.string() + ": cannot read its size: " + error.message());
    if (size > kMaxSceneFileBytes) {
        throw SceneError(path.string() + ": the file has " + std::to_string(size) +
                         " bytes; scene files are at most " + std::to_string(kMaxSceneFileBytes) +
                         " (256 MiB; docs/scene-format.md, Limits)");
    }
    std::ifstream file(path, std::ios::binary);
    if (!file) throw SceneError(path.string() + ": cannot open the scene file");
    // Read up to the cap and one byte more, whatever the size said: a file still being
    // written grows after its size was taken.
    std::string text(static_cast<std::size_t>(size), '\0');
    file.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(file.gcount()));
    for (char buffer[1 << 16]; file.read(buffer, sizeof buffer) || file.gcount() > 0;) {
        text.append(buffer, static_cast<std::size_t>(file.gcount()));
        if (text.size() > kMaxSceneFileBytes) {
            throw SceneError(path.string() + ": the file grew past " +
                             std::to_string(kMaxSceneFileBytes) +
                             " bytes while it was read; scene files are at most that (256 MiB; "
                             "docs/scene-format.md, Limits)");
        }
    }
    if (file.bad()) throw SceneError(path.string() + ": cannot read the file");
    return load(text, Source{path.string(), path.parent_path()});
}

Scene load_scene_from_string(std::string_view text, const std::string& name,
                             const std::filesystem::path& directory) {
    return load(text, Source{name, directory});
}

}  // namespace csgrt
