#pragma once

// Where tests write files (a folder of their own under the build tree's test_output), and
// reading a file back whole.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
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

/// The bytes of the file at `path`, read in binary mode: empty when it cannot be opened.
inline std::string file_contents(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace csgrt::test
