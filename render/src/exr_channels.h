#pragma once

// The channels of csgrt's EXR, shared by its writer (exr_write.cpp) and reader (exr.cpp).

#include <array>
#include <cstddef>
#include <string>

#include "csgrt/render/image.h"

namespace csgrt::detail {

/// A channel's place in the file and in a Pixel. Types are OpenEXR's pixel types.
enum class ExrPixelType { UnsignedInt, Half, Float };

struct ExrChannel {
    const char* name;
    /// The part it is written to: kExrImagePart or kExrIdPart.
    int part;
    ExrPixelType file_type;
    std::size_t offset;
    /// Read from files of earlier csgrt versions when the file lacks the channel that now
    /// holds the value; never written.
    bool legacy = false;
};

constexpr int kExrImagePart = 0;
constexpr int kExrIdPart = 1;
constexpr std::array<const char*, 2> kExrPartNames = {"rgba", "id"};

// The id has a part of its own: OpenImageIO gives a part one pixel type, and in a part of mixed
// types it converts a uint channel to float normalised by 2^32 - 1, which loses the ids.
// The cost is the layer "cost" with one channel per count (Nuke's and OpenImageIO's
// layer.channel rule: the last dot separates them); earlier files had one channel "cost".
// Every channel is a float in memory but the id (a uint).
constexpr std::array<ExrChannel, 14> kExrChannels = {{
    {"R", kExrImagePart, ExrPixelType::Half, offsetof(Pixel, red)},
    {"G", kExrImagePart, ExrPixelType::Half, offsetof(Pixel, green)},
    {"B", kExrImagePart, ExrPixelType::Half, offsetof(Pixel, blue)},
    {"A", kExrImagePart, ExrPixelType::Half, offsetof(Pixel, alpha)},
    {"Z", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, depth)},
    {"N.X", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, normal_x)},
    {"N.Y", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, normal_y)},
    {"N.Z", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, normal_z)},
    {"cost.nodes", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, cost_nodes)},
    {"cost.primitives", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, cost_primitives)},
    {"cost.solves", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, cost_solves)},
    {"cost.total", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, cost)},
    {"cost", kExrImagePart, ExrPixelType::Float, offsetof(Pixel, cost), true},
    {"id", kExrIdPart, ExrPixelType::UnsignedInt, offsetof(Pixel, object_id)},
}};

/// The names of a --cost-all layer's channels, in Pixel's order: "cost.<structure>.nodes", ...
inline std::array<std::string, 4> cost_layer_channels(const std::string& structure) {
    const std::string prefix = "cost." + structure + ".";
    return {prefix + "nodes", prefix + "primitives", prefix + "solves", prefix + "total"};
}

}  // namespace csgrt::detail
