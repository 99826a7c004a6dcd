#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>

namespace csgrt {

/// Where the csgrt program writes: results to `out`, errors and the progress bar to `err`.
/// The progress bar is drawn only when `err_is_terminal` and a render has run for
/// `progress_delay_seconds`, so short renders stay silent.
struct CommandLineStreams {
    std::ostream& out;
    std::ostream& err;
    bool err_is_terminal = false;
    double progress_delay_seconds = 1.0;
    /// Memory a render's image may take; 0 means the machine's free memory at the start. A larger
    /// image is refused before rendering, with the estimate.
    std::uint64_t memory_bytes = 0;
};

/// While alive, SIGINT and SIGTERM first remove the temporary files that write_render_files
/// makes beside `exr_path` (and its previews), then end the process as the signal would have;
/// the previous handlers come back on destruction. One at a time per process.
class TemporariesRemovedOnSignal {
public:
    explicit TemporariesRemovedOnSignal(const std::filesystem::path& exr_path);
    ~TemporariesRemovedOnSignal();
    TemporariesRemovedOnSignal(const TemporariesRemovedOnSignal&) = delete;
    TemporariesRemovedOnSignal& operator=(const TemporariesRemovedOnSignal&) = delete;
};

/// The csgrt program (docs/rendering.md): `render SCENE.json -o OUT.exr [options]`,
/// `info SCENE.json`, `validate SCENE.json`. Returns the exit status: 0 on success, 2 for a
/// usage error (a bad option or argument, a missing scene file), 1 for any other error; an
/// error is reported as one line "csgrt: error: ..." on `err`. Nothing is written to the output
/// paths unless the render succeeds, and then each file appears whole.
int run_csgrt(int argc, const char* const* argv, CommandLineStreams streams);

}  // namespace csgrt
