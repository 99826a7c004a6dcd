// libFuzzer target: one mesh reader (CSGRT_FUZZ_MESH_FORMAT: off, obj, ply or stl; CMake builds
// this file once per format), then validation, both precisions of Mesh and a few queries.

#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz/fuzz_harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    csgrt::fuzz::run_mesh(std::span<const std::uint8_t>(data, size), CSGRT_FUZZ_MESH_FORMAT);
    return 0;
}
