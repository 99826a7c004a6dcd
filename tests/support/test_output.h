#pragma once

// Where tests write files: a folder of their own under the build tree's test_output.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace csgrt::test {

/// A fresh, empty directory CSGRT_BINARY_DIR/test_output/`name` for one test's files.
inline std::filesystem::path fresh_directory(const std::string& name) {
    const std::filesystem::path path =
        std::filesystem::path(CSGRT_BINARY_DIR) / "test_output" / name;
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
    return path;
}

/// The names of the entries of `directory`, sorted.
inline std::vector<std::string> names_in(const std::filesystem::path& directory) {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(directory)) {
        names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace csgrt::test
