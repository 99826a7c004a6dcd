// libFuzzer target: the JSON scene loader (csg/scene_file.h), then commit and a few queries.
// Mesh paths in the input resolve against data/scenes, so the seeds' meshes load.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz/fuzz_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    csgrt::fuzz::run_scene(std::string_view(reinterpret_cast<const char*>(data), size),
                           CSGRT_SOURCE_DIR "/data/scenes");
    return 0;
}
