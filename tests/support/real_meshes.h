#pragma once

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace csgrt::test {

/// The path of the real mesh `name` ("armadillo", "bunny00"...) in data/meshes/, running
/// data/fetch-meshes first if it is missing. CTest runs tests in parallel processes, so the
/// script runs under an exclusive lock on data/meshes/.fetch.lock: no test reads a file that
/// another is still writing. Returns an empty path when the mesh cannot be had (no network);
/// callers then skip.
inline std::filesystem::path real_mesh(const std::string& name) {
    const std::filesystem::path source = CSGRT_SOURCE_DIR;
    const std::filesystem::path directory = source / "data" / "meshes";
    const std::filesystem::path path = directory / (name + ".off");
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    const int lock = ::open((directory / ".fetch.lock").c_str(), O_CREAT | O_RDWR, 0644);
    if (lock >= 0) ::flock(lock, LOCK_EX);
    if (!std::filesystem::exists(path)) {
        const std::string command =
            "bash '" + (source / "data" / "fetch-meshes").string() + "' >/dev/null 2>&1";
        [[maybe_unused]] const int status = std::system(command.c_str());
    }
    if (lock >= 0) {
        ::flock(lock, LOCK_UN);
        ::close(lock);
    }
    return std::filesystem::exists(path) ? path : std::filesystem::path();
}

}  // namespace csgrt::test
