#include "exr_write.h"

#include <Imath/half.h>
#include <OpenEXR/ImfIDManifestAttribute.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/openexr.h>
#include <libdeflate.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "exr_channels.h"
#include "exr_id_manifest.h"

namespace csgrt::detail {

namespace {

// The pixels are gathered as their bytes in memory, which EXR stores little endian.
static_assert(std::endian::native == std::endian::little,
              "exr_write.cpp copies pixel bytes as they are; a big-endian port must swap them");

/// zlib's fastest level, for the id manifest (one small block; libdeflate does the pixels).
constexpr int kManifestZipLevel = 1;

/// libdeflate's level for the pixel chunks. The same 160 MB of chunks on one core, seconds and
/// MB: a 2048^2 showcase frame, zlib level 1 (what OpenEXR 3.1 itself would use) 0.76-0.86 and
/// 24.2, libdeflate level 1 0.48-0.51 and 23.6, level 2 0.49-0.56 and 23.6, level 6 0.62 and
/// 23.1; an empty frame (every channel constant), libdeflate level 1 0.45-0.47, level 2
/// 0.28-0.29. Level 1 spends longer on long runs than level 2 (in fewer instructions:
/// callgrind 0.53G against 1.08G), and frames have flat regions. Any level decodes to the same
/// pixels: the chunks are zlib streams (RFC 1950), as EXR's ZIP compression defines them.
constexpr int kDeflateLevel = 2;

/// A channel as the chunk encoder reads it: `width` values a row from `base`, `stride` bytes
/// apart, rows `row_stride` bytes apart. Half channels are floats in memory, rounded to half
/// (Imath's round-to-nearest-even, as OpenEXR's own conversion) as they are gathered.
struct ChannelSource {
    std::string name;
    ExrPixelType type;
    const unsigned char* base;
    std::size_t stride;
    std::size_t row_stride;
};

std::size_t bytes_per_value(ExrPixelType type) {
    return type == ExrPixelType::Half ? 2 : 4;
}

exr_pixel_type_t core_type(ExrPixelType type) {
    switch (type) {
        case ExrPixelType::UnsignedInt:
            return EXR_PIXEL_UINT;
        case ExrPixelType::Half:
            return EXR_PIXEL_HALF;
        case ExrPixelType::Float:
            return EXR_PIXEL_FLOAT;
    }
    return EXR_PIXEL_FLOAT;
}

struct CompressorDeleter {
    void operator()(libdeflate_compressor* compressor) const {
        libdeflate_free_compressor(compressor);
    }
};

/// One thread's buffers for encoding chunks: reused from chunk to chunk.
struct ChunkScratch {
    std::unique_ptr<libdeflate_compressor, CompressorDeleter> compressor;
    std::vector<unsigned char> split;
    std::vector<unsigned char> predicted;
    std::vector<unsigned char> compressed;

    ChunkScratch() : compressor(libdeflate_alloc_compressor(kDeflateLevel)) {
        if (!compressor) throw std::bad_alloc();
    }
};

/// One chunk of `lines` scanlines from `first_line` as EXR's ZIP compression stores it
/// (OpenEXR's ImfZip.cpp, the format's definition): the uncompressed chunk is every line's
/// channels in the part's (alphabetical) order, each channel's values little endian; its bytes
/// are split into the even-indexed ones followed by the odd-indexed ones, each byte replaced by
/// its difference from the one before plus 128 (mod 256), and the result zlib-compressed. A
/// chunk that does not get smaller is stored as the uncompressed chunk, which readers tell by
/// its size. The gather writes the split order directly: every channel row is an even number
/// of bytes, so a value's bytes alternate between the two halves from its first.
std::vector<unsigned char> encode_chunk(std::span<const ChannelSource> channels, int width,
                                        int first_line, int lines, ChunkScratch& scratch) {
    std::size_t size = 0;
    for (const ChannelSource& channel : channels) size += bytes_per_value(channel.type);
    size *= static_cast<std::size_t>(width) * static_cast<std::size_t>(lines);
    scratch.split.resize(size);
    unsigned char* even = scratch.split.data();
    unsigned char* odd = even + size / 2;
    for (int line = first_line; line < first_line + lines; ++line) {
        for (const ChannelSource& channel : channels) {
            const unsigned char* value = channel.base + std::size_t(line) * channel.row_stride;
            if (channel.type == ExrPixelType::Half) {
                for (int x = 0; x < width; ++x, value += channel.stride) {
                    float linear;
                    std::memcpy(&linear, value, sizeof(linear));
                    const std::uint16_t bits = half(linear).bits();
                    *even++ = static_cast<unsigned char>(bits & 0xff);
                    *odd++ = static_cast<unsigned char>(bits >> 8);
                }
            } else {
                // Bytes 0 and 2 of the value to the even half, 1 and 3 to the odd: one load
                // and two 16-bit stores (byte by byte it was a fifth of the write's time).
                for (int x = 0; x < width; ++x, value += channel.stride) {
                    std::uint32_t bits;
                    std::memcpy(&bits, value, sizeof(bits));
                    const auto low =
                        static_cast<std::uint16_t>((bits & 0xffu) | ((bits >> 8) & 0xff00u));
                    const auto high = static_cast<std::uint16_t>(((bits >> 8) & 0xffu) |
                                                                 ((bits >> 16) & 0xff00u));
                    std::memcpy(even, &low, sizeof(low));
                    std::memcpy(odd, &high, sizeof(high));
                    even += 2;
                    odd += 2;
                }
            }
        }
    }
    scratch.predicted.resize(size);
    const unsigned char* split = scratch.split.data();
    unsigned char* predicted = scratch.predicted.data();
    if (size > 0) predicted[0] = split[0];
    for (std::size_t i = 1; i < size; ++i) {
        predicted[i] = static_cast<unsigned char>(split[i] - split[i - 1] + 128);
    }
    scratch.compressed.resize(libdeflate_zlib_compress_bound(scratch.compressor.get(), size));
    const std::size_t compressed =
        libdeflate_zlib_compress(scratch.compressor.get(), predicted, size,
                                 scratch.compressed.data(), scratch.compressed.size());
    if (compressed > 0 && compressed < size) {
        return std::vector<unsigned char>(scratch.compressed.begin(),
                                          scratch.compressed.begin() + std::ptrdiff_t(compressed));
    }
    // Stored: the bytes in their own order again.
    std::vector<unsigned char> stored(size);
    for (std::size_t i = 0; i < size / 2; ++i) {
        stored[2 * i] = split[i];
        stored[2 * i + 1] = split[size / 2 + i];
    }
    return stored;
}

/// An OpenEXR Core write context that reports its errors as exceptions and is finished (its
/// chunk tables written, the file closed) exactly once.
class CoreWriter {
public:
    explicit CoreWriter(const std::filesystem::path& path) {
        exr_context_initializer_t initializer = EXR_DEFAULT_CONTEXT_INITIALIZER;
        initializer.error_handler_fn = &CoreWriter::record;
        initializer.user_data = &message_;
        check(exr_start_write(&context_, path.c_str(), EXR_WRITE_FILE_DIRECTLY, &initializer),
              "cannot create the file");
    }
    ~CoreWriter() {
        if (context_ != nullptr) exr_finish(&context_);
    }
    CoreWriter(const CoreWriter&) = delete;
    CoreWriter& operator=(const CoreWriter&) = delete;

    exr_context_t get() const { return context_; }

    void check(exr_result_t result, const std::string& what) {
        if (result == EXR_ERR_SUCCESS) return;
        const std::string detail =
            message_.empty() ? std::string(exr_get_default_error_message(result)) : message_;
        throw std::runtime_error(what + ": " + detail);
    }

    void finish() {
        const exr_result_t result = exr_finish(&context_);
        context_ = nullptr;
        check(result, "cannot finish the file");
    }

private:
    static void record(exr_const_context_t context, exr_result_t code, const char* message) {
        void* user = nullptr;
        if (exr_get_user_data(context, &user) != EXR_ERR_SUCCESS || user == nullptr) return;
        *static_cast<std::string*>(user) =
            message != nullptr ? message : exr_get_default_error_message(code);
    }

    exr_context_t context_ = nullptr;
    std::string message_;
};

/// OpenEXR's world-to-camera matrix: camera at the origin, x right, y up, z along the view
/// (left-handed, as RenderMan), for row vectors (p' = p M) as Imath stores matrices, row by row.
exr_attr_m44f_t world_to_camera(const Camera& camera) {
    const Vector3 forward = (camera.look_at - camera.position).normalized();
    const Vector3 right = forward.cross(camera.up).normalized();
    const Vector3 up = right.cross(forward);
    const std::array<Vector3, 3> axes = {right, up, forward};
    exr_attr_m44f_t matrix{};
    for (int i = 0; i < 4; ++i) matrix.m[5 * i] = 1.0f;
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) matrix.m[4 * i + j] = static_cast<float>(axes[j][i]);
        matrix.m[12 + j] = static_cast<float>(-axes[j].dot(camera.position));
    }
    return matrix;
}

exr_attr_v3d_t to_core(const Vector3& v) {
    exr_attr_v3d_t result;
    result.arr[0] = v.x();
    result.arr[1] = v.y();
    result.arr[2] = v.z();
    return result;
}

/// The id manifest's attribute value, serialised by OpenEXR's own attribute class.
std::vector<char> manifest_attribute(const ExrMetadata& metadata) {
    class Bytes : public Imf::OStream {
    public:
        Bytes() : Imf::OStream("idManifest") {}
        void write(const char c[], int n) override {
            if (position_ + std::uint64_t(n) > bytes.size()) bytes.resize(position_ + n);
            std::copy(c, c + n, bytes.begin() + std::ptrdiff_t(position_));
            position_ += std::uint64_t(n);
        }
        std::uint64_t tellp() override { return position_; }
        void seekp(std::uint64_t position) override { position_ = position; }
        std::vector<char> bytes;

    private:
        std::uint64_t position_ = 0;
    };
    const Imf::IDManifestAttribute attribute(id_manifest(metadata, kManifestZipLevel));
    Bytes bytes;
    attribute.writeValueTo(bytes, 2);
    return std::move(bytes.bytes);
}

/// The header of both parts: what exr.h documents, in the attribute types OpenEXR's C++
/// library gave them when it wrote these files.
void write_header(CoreWriter& writer, const Image& image, const ExrMetadata& metadata,
                  std::span<const CostLayer> cost_layers,
                  const std::array<std::vector<ChannelSource>, 2>& channels) {
    exr_context_t context = writer.get();
    // Names longer than 31 bytes (cost.<structure>.buildMilliseconds) need the long-name flag.
    bool long_names = false;
    for (const auto& part : channels) {
        for (const ChannelSource& channel : part) long_names |= channel.name.size() > 31;
    }
    for (const CostLayer& layer : cost_layers) {
        long_names |= ("cost." + layer.structure + ".buildMilliseconds").size() > 31;
        long_names |= ("cost." + layer.structure + ".traceMilliseconds").size() > 31;
    }
    writer.check(exr_set_longname_support(context, long_names ? 1 : 0), "long names");
    const std::vector<char> manifest = manifest_attribute(metadata);
    exr_attr_box2i_t window;
    window.min.arr[0] = 0;
    window.min.arr[1] = 0;
    window.max.arr[0] = image.width() - 1;
    window.max.arr[1] = image.height() - 1;
    exr_attr_v2f_t centre;
    centre.arr[0] = 0.0f;
    centre.arr[1] = 0.0f;
    for (std::size_t part = 0; part < kExrPartNames.size(); ++part) {
        const std::string name = kExrPartNames[part];
        int index = 0;
        writer.check(exr_add_part(context, name.c_str(), EXR_STORAGE_SCANLINE, &index),
                     "cannot add the part '" + name + "'");
        for (const ChannelSource& channel : channels[part]) {
            writer.check(
                exr_add_channel(context, index, channel.name.c_str(), core_type(channel.type),
                                EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1),
                "cannot add the channel '" + channel.name + "'");
        }
        // The required attributes one by one, in the order OpenEXR's C++ library wrote them
        // (by name), for the idManifest's sake: OpenEXR 3.1's reader of that attribute reads
        // 4 bytes past its value (it subtracts 4 for the 8-byte size it reads first; fixed
        // upstream), which cost the next attribute's name its first 4 bytes. That attribute
        // is lineOrder, as before, whose loss leaves the default, increasing y, which the
        // file has; written last, Core's chunkCount would be lost and the part unreadable.
        const std::string what = "cannot set the required attributes of '" + name + "'";
        writer.check(exr_set_compression(context, index, EXR_COMPRESSION_ZIP), what);
        writer.check(exr_set_data_window(context, index, &window), what);
        writer.check(exr_set_display_window(context, index, &window), what);
        if (int(part) == kExrIdPart) {
            writer.check(
                exr_attr_set_user(context, index, "idManifest", "idmanifest",
                                  static_cast<std::int32_t>(manifest.size()), manifest.data()),
                "cannot set the attribute 'idManifest'");
        }
        writer.check(exr_set_lineorder(context, index, EXR_LINEORDER_INCREASING_Y), what);
        writer.check(exr_set_pixel_aspect_ratio(context, index, 1.0f), what);
        writer.check(exr_set_screen_window_center(context, index, &centre), what);
        writer.check(exr_set_screen_window_width(context, index, 1.0f), what);
    }
    const int part = kExrImagePart;
    const auto check = [&](exr_result_t result, const char* name) {
        writer.check(result, std::string("cannot set the attribute '") + name + "'");
    };
    exr_attr_v2i_t resolution;
    resolution.arr[0] = image.width();
    resolution.arr[1] = image.height();
    check(exr_attr_set_v2i(context, part, "resolution", &resolution), "resolution");
    const Camera& camera = metadata.camera;
    const bool pinhole = camera.projection == Camera::Projection::Pinhole;
    check(exr_attr_set_string(context, part, "cameraProjection",
                              pinhole ? "pinhole" : "orthographic"),
          "cameraProjection");
    const exr_attr_v3d_t position = to_core(camera.position);
    const exr_attr_v3d_t look_at = to_core(camera.look_at);
    const exr_attr_v3d_t up = to_core(camera.up);
    check(exr_attr_set_v3d(context, part, "cameraPosition", &position), "cameraPosition");
    check(exr_attr_set_v3d(context, part, "cameraLookAt", &look_at), "cameraLookAt");
    check(exr_attr_set_v3d(context, part, "cameraUp", &up), "cameraUp");
    if (pinhole) {
        check(exr_attr_set_double(context, part, "cameraVerticalFov", camera.vertical_fov_degrees),
              "cameraVerticalFov");
    } else {
        check(exr_attr_set_double(context, part, "cameraOrthographicHeight",
                                  camera.orthographic_height),
              "cameraOrthographicHeight");
    }
    const exr_attr_m44f_t world = world_to_camera(camera);
    check(exr_attr_set_m44f(context, part, "worldToCamera", &world), "worldToCamera");
    check(exr_attr_set_string(context, part, "accelerator", metadata.accelerator.c_str()),
          "accelerator");
    // Timings differ from run to run: only when asked, so identical renders give identical files.
    if (metadata.include_timing) {
        check(exr_attr_set_double(context, part, "acceleratorBuildMs",
                                  metadata.accelerator_build_milliseconds),
              "acceleratorBuildMs");
        check(exr_attr_set_double(context, part, "renderSeconds", metadata.render_seconds),
              "renderSeconds");
    }
    check(exr_attr_set_int(context, part, "samplesPerPixel", metadata.samples_per_pixel),
          "samplesPerPixel");
    check(exr_attr_set_string(context, part, "scene", metadata.scene.c_str()), "scene");
    // --cost-all: each layer's build and trace times (timings, asked for).
    for (const CostLayer& layer : cost_layers) {
        const std::string built = "cost." + layer.structure + ".buildMilliseconds";
        const std::string traced = "cost." + layer.structure + ".traceMilliseconds";
        check(exr_attr_set_double(context, part, built.c_str(), layer.build_milliseconds),
              built.c_str());
        check(exr_attr_set_double(context, part, traced.c_str(), layer.trace_milliseconds),
              traced.c_str());
    }
    writer.check(exr_write_header(context), "cannot write the header");
}

/// Every part's channels as the encoder reads them, in file (alphabetical) order.
std::array<std::vector<ChannelSource>, 2> channel_sources(const Image& image,
                                                          std::span<const CostLayer> cost_layers) {
    std::array<std::vector<ChannelSource>, 2> parts;
    const auto* pixels = reinterpret_cast<const unsigned char*>(image.pixels().data());
    const std::size_t width = static_cast<std::size_t>(image.width());
    for (const ExrChannel& channel : kExrChannels) {
        if (channel.legacy) continue;
        parts[channel.part].push_back({channel.name, channel.file_type, pixels + channel.offset,
                                       sizeof(Pixel), sizeof(Pixel) * width});
    }
    for (const CostLayer& layer : cost_layers) {
        if (layer.width != image.width() || layer.height != image.height() ||
            layer.nodes.size() != image.pixel_count() ||
            layer.primitives.size() != image.pixel_count() ||
            layer.solves.size() != image.pixel_count() ||
            layer.total.size() != image.pixel_count()) {
            throw std::runtime_error("cost layer '" + layer.structure + "' is " +
                                     std::to_string(layer.width) + "x" +
                                     std::to_string(layer.height) + ", not the image's size");
        }
        const std::array<std::string, 4> names = cost_layer_channels(layer.structure);
        const std::array<const std::vector<float>*, 4> values = {&layer.nodes, &layer.primitives,
                                                                 &layer.solves, &layer.total};
        for (std::size_t c = 0; c < names.size(); ++c) {
            parts[kExrImagePart].push_back(
                {names[c], ExrPixelType::Float,
                 reinterpret_cast<const unsigned char*>(values[c]->data()), sizeof(float),
                 sizeof(float) * width});
        }
    }
    // EXR's channel lists are sorted by name, bytewise (strcmp), and so is each line's data.
    for (auto& part : parts) {
        std::sort(part.begin(), part.end(),
                  [](const ChannelSource& a, const ChannelSource& b) { return a.name < b.name; });
    }
    return parts;
}

}  // namespace

void write_exr_file(const std::filesystem::path& path, const Image& image,
                    const ExrMetadata& metadata, std::span<const CostLayer> cost_layers) {
    const std::array<std::vector<ChannelSource>, 2> channels = channel_sources(image, cost_layers);
    CoreWriter writer(path);
    write_header(writer, image, metadata, cost_layers, channels);
    exr_context_t context = writer.get();

    struct Chunk {
        int part;
        int first_line;
        int lines;
    };
    std::vector<Chunk> chunks;
    for (int part = 0; part < int(channels.size()); ++part) {
        // The layout's own lines per chunk (16 for ZIP), and the file's order of chunks.
        std::int32_t lines_per_chunk = 0;
        writer.check(exr_get_scanlines_per_chunk(context, part, &lines_per_chunk),
                     "lines per chunk");
        for (int line = 0; line < image.height(); line += lines_per_chunk) {
            chunks.push_back({part, line, std::min(lines_per_chunk, image.height() - line)});
        }
    }
    // Chunks are independent: encoded on every thread and written in order as they come, so
    // the file's bytes do not depend on the thread count, and at most a few chunks a thread
    // are held (all of a 16384^2 frame's would be as large as its image).
    struct Encoded {
        std::size_t index = 0;
        std::vector<unsigned char> bytes;
    };
    tbb::enumerable_thread_specific<ChunkScratch> scratch;
    std::size_t next = 0;
    const auto in_flight = static_cast<std::size_t>(4 * tbb::this_task_arena::max_concurrency());
    tbb::parallel_pipeline(
        in_flight,
        tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                            [&](tbb::flow_control& control) -> std::size_t {
                                                if (next == chunks.size()) control.stop();
                                                return next++;
                                            }) &
            tbb::make_filter<std::size_t, Encoded>(
                tbb::filter_mode::parallel,
                [&](std::size_t i) {
                    const Chunk& chunk = chunks[i];
                    return Encoded{i, encode_chunk(channels[chunk.part], image.width(),
                                                   chunk.first_line, chunk.lines, scratch.local())};
                }) &
            tbb::make_filter<Encoded, void>(
                tbb::filter_mode::serial_in_order, [&](const Encoded& encoded) {
                    const Chunk& chunk = chunks[encoded.index];
                    writer.check(
                        exr_write_scanline_chunk(context, chunk.part, chunk.first_line,
                                                 encoded.bytes.data(), encoded.bytes.size()),
                        "cannot write the lines from " + std::to_string(chunk.first_line));
                }));
    writer.finish();
}

}  // namespace csgrt::detail
