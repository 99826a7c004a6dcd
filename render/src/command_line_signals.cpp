#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <string>

#include "csgrt/render/command_line.h"
#include "csgrt/render/exr.h"

namespace csgrt {

namespace fs = std::filesystem;

namespace {

// The handler may only call async-signal-safe functions, so everything it needs is prepared
// beforehand in these fixed buffers: the folder, opened, and the name prefixes.
int signal_directory = -1;
char signal_prefixes[4][512];
int signal_prefix_count = 0;
struct sigaction previous_interrupt, previous_terminate;

/// Removes the folder's entries that start with one of the prefixes, then dies of the signal
/// as it would have without the handler.
extern "C" void remove_temporaries_and_die(int signal) {
    if (signal_directory >= 0) {
        alignas(8) char buffer[4096];
        ::lseek(signal_directory, 0, SEEK_SET);
        long bytes;
        while ((bytes = ::syscall(SYS_getdents64, signal_directory, buffer, sizeof buffer)) > 0) {
            for (long offset = 0; offset < bytes;) {
                const auto* entry = reinterpret_cast<const struct dirent64*>(buffer + offset);
                for (int p = 0; p < signal_prefix_count; ++p) {
                    if (std::strncmp(entry->d_name, signal_prefixes[p],
                                     std::strlen(signal_prefixes[p])) == 0) {
                        ::unlinkat(signal_directory, entry->d_name, 0);
                    }
                }
                offset += entry->d_reclen;
            }
        }
    }
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

}  // namespace

TemporariesRemovedOnSignal::TemporariesRemovedOnSignal(const std::filesystem::path& exr_path) {
    const fs::path directory =
        exr_path.parent_path().empty() ? fs::path(".") : exr_path.parent_path();
    signal_directory = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    signal_prefix_count = 0;
    // exr.cpp's TemporaryFile names: ".<target name>.tmp-<pid>-<counter>".
    for (const fs::path& target : render_file_paths(exr_path, true)) {
        // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chained string +.
        std::string prefix = ".";
        prefix.append(target.filename().string()).append(".tmp-");
        prefix.append(std::to_string(::getpid())).append("-");
        if (prefix.size() >= sizeof signal_prefixes[0]) continue;
        std::memcpy(signal_prefixes[signal_prefix_count], prefix.c_str(), prefix.size() + 1);
        ++signal_prefix_count;
    }
    struct sigaction action {};
    action.sa_handler = remove_temporaries_and_die;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, &previous_interrupt);
    ::sigaction(SIGTERM, &action, &previous_terminate);
}

TemporariesRemovedOnSignal::~TemporariesRemovedOnSignal() {
    ::sigaction(SIGINT, &previous_interrupt, nullptr);
    ::sigaction(SIGTERM, &previous_terminate, nullptr);
    if (signal_directory >= 0) ::close(signal_directory);
    signal_directory = -1;
    signal_prefix_count = 0;
}

}  // namespace csgrt
