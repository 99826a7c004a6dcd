#include "csgrt/render/exr.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIDManifest.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <Imath/half.h>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/test_output.h"

namespace csgrt {
namespace {

using test::fresh_directory;
using test::names_in;

/// A 5 x 3 image whose every channel varies per pixel, with background pixels mixed in.
Image sample_image() {
    Image image(5, 3);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 5; ++x) {
            Pixel& pixel = image.at(x, y);
            if ((x + y) % 4 == 3) {
                pixel.cost = 2.0f;  // background: default depth, normal and id
                continue;
            }
            pixel.red = 0.1f * x + 0.3337f;
            pixel.green = 1.0f / (y + 3.0f);
            pixel.blue = 12.5f;  // above 1: HDR values survive
            pixel.alpha = 1.0f;
            pixel.depth = 1.0f + 0.123456789f * (x + 5 * y);
            const Vector3 n = Vector3(x - 2.0, y - 1.0, 1.5).normalized();
            pixel.normal_x = float(n.x());
            pixel.normal_y = float(n.y());
            pixel.normal_z = float(n.z());
            pixel.object_id = 1000000u * x + 7u * y;  // beyond float's exact integers
            pixel.cost_nodes = float(3 * x);
            pixel.cost_primitives = float(y + 1);
            pixel.cost_solves = float(x * y);
            pixel.cost = pixel.cost_nodes + pixel.cost_primitives + pixel.cost_solves;
        }
    }
    return image;
}

ExrMetadata sample_metadata() {
    ExrMetadata metadata;
    metadata.camera.position = Point3(1, 2, 10);
    metadata.camera.look_at = Point3(1, 2, 0);
    metadata.camera.up = Vector3(0, 1, 0);
    metadata.camera.vertical_fov_degrees = 35.0;
    metadata.accelerator = "brute";
    metadata.include_timing = true;
    metadata.accelerator_build_milliseconds = 1.25;
    metadata.render_seconds = 0.5;
    metadata.samples_per_pixel = 16;
    metadata.scene = "sample.json";
    metadata.objects = {{"ground", "plane", "floor"}, {"ball", "sphere", "red"}};
    return metadata;
}

TEST(WriteExr, WritesTheDocumentedChannelsAndAttributes) {
    const auto directory = fresh_directory("exr_channels");
    const Image image = sample_image();
    write_exr(directory / "out.exr", image, sample_metadata());
    // Nothing but the file itself is left behind.
    EXPECT_EQ(names_in(directory), std::vector<std::string>{"out.exr"});

    // Read with OpenEXR directly, independently of read_exr. A one-part reader sees the
    // first part, "rgba"; the id is in the second.
    Imf::InputFile file((directory / "out.exr").c_str());
    const Imf::Header& header = file.header();
    const Imf::ChannelList& channels = header.channels();
    const std::vector<std::pair<std::string, Imf::PixelType>> expected = {
        {"A", Imf::HALF},
        {"B", Imf::HALF},
        {"G", Imf::HALF},
        {"N.X", Imf::FLOAT},
        {"N.Y", Imf::FLOAT},
        {"N.Z", Imf::FLOAT},
        {"R", Imf::HALF},
        {"Z", Imf::FLOAT},
        {"cost.nodes", Imf::FLOAT},
        {"cost.primitives", Imf::FLOAT},
        {"cost.solves", Imf::FLOAT},
        {"cost.total", Imf::FLOAT}};
    std::vector<std::pair<std::string, Imf::PixelType>> found;
    for (auto it = channels.begin(); it != channels.end(); ++it) {
        found.emplace_back(it.name(), it.channel().type);
    }
    EXPECT_EQ(found, expected);  // ChannelList iterates in name order

    const Imath::Box2i window = header.dataWindow();
    EXPECT_EQ(window.min, Imath::V2i(0, 0));
    EXPECT_EQ(window.max, Imath::V2i(4, 2));
    EXPECT_EQ(header.typedAttribute<Imf::V2iAttribute>("resolution").value(), Imath::V2i(5, 3));
    EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>("cameraProjection").value(), "pinhole");
    EXPECT_EQ(header.typedAttribute<Imf::V3dAttribute>("cameraPosition").value(),
              Imath::V3d(1, 2, 10));
    EXPECT_EQ(header.typedAttribute<Imf::DoubleAttribute>("cameraVerticalFov").value(), 35.0);
    EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>("accelerator").value(), "brute");
    EXPECT_EQ(header.typedAttribute<Imf::DoubleAttribute>("acceleratorBuildMs").value(), 1.25);
    EXPECT_EQ(header.typedAttribute<Imf::IntAttribute>("samplesPerPixel").value(), 16);
    EXPECT_EQ(header.typedAttribute<Imf::StringAttribute>("scene").value(), "sample.json");
    // worldToCamera (row vectors, camera looking along +z): the camera sits at the origin, the
    // point looked at is 10 ahead, and a point to the world's +x is to the camera's right.
    ASSERT_TRUE(Imf::hasWorldToCamera(header));
    const Imath::M44f& world_to_camera = Imf::worldToCamera(header);
    const Imath::V3f at_camera = Imath::V3f(1, 2, 10) * world_to_camera;
    const Imath::V3f ahead = Imath::V3f(1, 2, 0) * world_to_camera;
    const Imath::V3f right = Imath::V3f(2, 2, 10) * world_to_camera;
    EXPECT_LT(at_camera.length(), 1e-6f);
    EXPECT_LT((ahead - Imath::V3f(0, 0, 10)).length(), 1e-5f);
    EXPECT_LT((right - Imath::V3f(1, 0, 0)).length(), 1e-6f);

    // Pixels: colour rounded to half, everything else exact.
    std::vector<float> red(15), depth(15), cost(15), solves(15);
    std::vector<std::uint32_t> id(15);
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(red.data()),
                                        sizeof(float), 5 * sizeof(float)));
    frame_buffer.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(depth.data()),
                                        sizeof(float), 5 * sizeof(float)));
    frame_buffer.insert("cost.total", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(cost.data()),
                                                 sizeof(float), 5 * sizeof(float)));
    frame_buffer.insert(
        "cost.solves", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(solves.data()), sizeof(float),
                                  5 * sizeof(float)));
    file.setFrameBuffer(frame_buffer);
    file.readPixels(0, 2);
    Imf::MultiPartInputFile parts((directory / "out.exr").c_str());
    ASSERT_EQ(parts.parts(), 2);
    EXPECT_EQ(parts.header(0).name(), "rgba");
    EXPECT_EQ(parts.header(1).name(), "id");
    const Imf::ChannelList& id_channels = parts.header(1).channels();
    ASSERT_NE(id_channels.findChannel("id"), nullptr);
    EXPECT_EQ(id_channels.findChannel("id")->type, Imf::UINT);
    int id_channel_count = 0;
    for (auto it = id_channels.begin(); it != id_channels.end(); ++it) ++id_channel_count;
    EXPECT_EQ(id_channel_count, 1);
    Imf::FrameBuffer id_buffer;
    id_buffer.insert("id", Imf::Slice(Imf::UINT, reinterpret_cast<char*>(id.data()),
                                      sizeof(std::uint32_t), 5 * sizeof(std::uint32_t)));
    Imf::InputPart id_part(parts, 1);
    id_part.setFrameBuffer(id_buffer);
    id_part.readPixels(0, 2);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 5; ++x) {
            const Pixel& pixel = image.at(x, y);
            const int i = 5 * y + x;
            EXPECT_EQ(red[i], float(half(pixel.red)));
            EXPECT_EQ(depth[i], pixel.depth);
            EXPECT_EQ(cost[i], pixel.cost);
            EXPECT_EQ(solves[i], pixel.cost_solves);
            EXPECT_EQ(id[i], pixel.object_id);
        }
    }
    EXPECT_EQ(depth[3], std::numeric_limits<float>::infinity());  // background
    EXPECT_EQ(id[3], 4294967295u);
}

TEST(ReadExr, RoundTripsPixelsAndMetadata) {
    const auto directory = fresh_directory("exr_round_trip");
    const Image image = sample_image();
    ExrMetadata metadata = sample_metadata();
    metadata.camera.projection = Camera::Projection::Orthographic;
    metadata.camera.orthographic_height = 3.5;
    write_exr(directory / "out.exr", image, metadata);
    const ExrFile file = read_exr(directory / "out.exr");
    ASSERT_EQ(file.image.width(), 5);
    ASSERT_EQ(file.image.height(), 3);
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        const Pixel& a = image.pixels()[i];
        const Pixel& b = file.image.pixels()[i];
        EXPECT_EQ(b.green, float(half(a.green)));
        EXPECT_EQ(b.blue, float(half(a.blue)));
        EXPECT_EQ(b.alpha, float(half(a.alpha)));
        EXPECT_EQ(b.depth, a.depth);
        EXPECT_EQ(b.normal_x, a.normal_x);
        EXPECT_EQ(b.normal_y, a.normal_y);
        EXPECT_EQ(b.normal_z, a.normal_z);
        EXPECT_EQ(b.object_id, a.object_id);
        EXPECT_EQ(b.cost, a.cost);
        EXPECT_EQ(b.cost_nodes, a.cost_nodes);
        EXPECT_EQ(b.cost_primitives, a.cost_primitives);
        EXPECT_EQ(b.cost_solves, a.cost_solves);
    }
    EXPECT_EQ(file.metadata.camera.projection, Camera::Projection::Orthographic);
    EXPECT_EQ(file.metadata.camera.orthographic_height, 3.5);
    EXPECT_EQ(file.metadata.camera.position, Point3(1, 2, 10));
    EXPECT_EQ(file.metadata.camera.look_at, Point3(1, 2, 0));
    EXPECT_EQ(file.metadata.accelerator, "brute");
    EXPECT_EQ(file.metadata.samples_per_pixel, 16);
}

TEST(ReadExr, ReadsTheOneCostChannelOfEarlierFilesAsTheTotal) {
    // Files before the cost layer had one channel "cost" (the top-level structure's count).
    const auto directory = fresh_directory("exr_legacy_cost");
    const std::filesystem::path path = directory / "old.exr";
    std::vector<float> cost = {1.0f, 2.0f, 40.0f, 7.0f};
    {
        Imf::Header header(2, 2);
        header.channels().insert("cost", Imf::Channel(Imf::FLOAT));
        Imf::OutputFile file(path.c_str(), header);
        Imf::FrameBuffer frame_buffer;
        frame_buffer.insert("cost", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(cost.data()),
                                               sizeof(float), 2 * sizeof(float)));
        file.setFrameBuffer(frame_buffer);
        file.writePixels(2);
    }
    const Image image = read_exr(path).image;
    for (std::size_t i = 0; i < cost.size(); ++i) {
        EXPECT_EQ(image.pixels()[i].cost, cost[i]);
        EXPECT_EQ(image.pixels()[i].cost_nodes, 0.0f);  // not in the file: the default
    }
}

TEST(WriteExr, TheIdManifestNamesEveryObject) {
    const auto directory = fresh_directory("exr_manifest");
    write_exr(directory / "out.exr", sample_image(), sample_metadata());
    // Read with OpenEXR's own manifest class, independently of read_exr.
    Imf::MultiPartInputFile parts((directory / "out.exr").c_str());
    ASSERT_TRUE(Imf::hasIDManifest(parts.header(1)));
    EXPECT_FALSE(Imf::hasIDManifest(parts.header(0)));
    const Imf::IDManifest manifest(Imf::idManifest(parts.header(1)));
    ASSERT_EQ(manifest.size(), 1u);
    const auto& group = manifest[0];
    EXPECT_EQ(group.getChannels(), std::set<std::string>{"id"});
    EXPECT_EQ(group.getComponents(), (std::vector<std::string>{"name", "shape", "material"}));
    EXPECT_EQ(group.getEncodingScheme(), Imf::IDManifest::ID_SCHEME);
    EXPECT_EQ(group.getHashScheme(), Imf::IDManifest::NOTHASHED);
    ASSERT_EQ(group.size(), 2u);
    EXPECT_EQ(group.find(0).text(), (std::vector<std::string>{"ground", "plane", "floor"}));
    EXPECT_EQ(group.find(1).text(), (std::vector<std::string>{"ball", "sphere", "red"}));

    const ExrFile file = read_exr(directory / "out.exr");
    ASSERT_EQ(file.metadata.objects.size(), 2u);
    EXPECT_EQ(file.metadata.objects[1].name, "ball");
    EXPECT_EQ(file.metadata.objects[1].shape, "sphere");
    EXPECT_EQ(file.metadata.objects[1].material, "red");
}

TEST(WriteExr, IdenticalImagesGiveByteIdenticalFilesWithoutTimings) {
    const auto directory = fresh_directory("exr_identical");
    ExrMetadata metadata = sample_metadata();
    metadata.include_timing = false;
    metadata.accelerator_build_milliseconds = 1.0;
    write_exr(directory / "a.exr", sample_image(), metadata);
    metadata.accelerator_build_milliseconds = 2.0;  // a different timing: not in the file
    metadata.render_seconds = 7.0;
    write_exr(directory / "b.exr", sample_image(), metadata);
    const std::string a = test::file_contents(directory / "a.exr");
    EXPECT_GT(a.size(), 100u);
    EXPECT_EQ(a, test::file_contents(directory / "b.exr"));
    Imf::InputFile file((directory / "a.exr").c_str());
    EXPECT_TRUE(file.header().find("acceleratorBuildMs") == file.header().end());
    EXPECT_TRUE(file.header().find("renderSeconds") == file.header().end());
    EXPECT_FALSE(read_exr(directory / "a.exr").metadata.include_timing);

    metadata.include_timing = true;  // asked for: recorded, and read back
    write_exr(directory / "c.exr", sample_image(), metadata);
    const ExrFile timed = read_exr(directory / "c.exr");
    EXPECT_TRUE(timed.metadata.include_timing);
    EXPECT_EQ(timed.metadata.accelerator_build_milliseconds, 2.0);
    EXPECT_EQ(timed.metadata.render_seconds, 7.0);
}

TEST(WriteExr, LeavesNothingWhenTheDirectoryIsMissing) {
    const auto directory = fresh_directory("exr_missing");
    try {
        write_exr(directory / "no" / "out.exr", sample_image(), sample_metadata());
        FAIL() << "no exception";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find("out.exr"), std::string::npos) << error.what();
    }
    EXPECT_TRUE(names_in(directory).empty());
}

TEST(WriteExr, ReplacesAnExistingFileWhole) {
    const auto directory = fresh_directory("exr_replace");
    {
        std::ofstream old(directory / "out.exr");
        old << "old contents";
    }
    write_exr(directory / "out.exr", sample_image(), sample_metadata());
    EXPECT_EQ(read_exr(directory / "out.exr").image.width(), 5);
    EXPECT_EQ(names_in(directory), std::vector<std::string>{"out.exr"});
}

TEST(WriteRenderFiles, WritesTheExrAndBothPreviewsBesideIt) {
    const auto directory = fresh_directory("exr_render_files");
    write_render_files(directory / "frame.exr", sample_image(), sample_metadata());
    EXPECT_EQ(names_in(directory),
              (std::vector<std::string>{"frame.cost.png", "frame.exr", "frame.png"}));
    EXPECT_EQ(colour_preview_path("a/b/out.exr"), std::filesystem::path("a/b/out.png"));
    EXPECT_EQ(cost_preview_path("a/b/out.exr"), std::filesystem::path("a/b/out.cost.png"));
}

TEST(WriteRenderFiles, WritesNoneWhenOneTargetCannotBeWritten) {
    const auto directory = fresh_directory("exr_render_files_blocked");
    // A directory where the cost preview should go: that file cannot be created.
    std::filesystem::create_directory(directory / "frame.cost.png");
    EXPECT_THROW(write_render_files(directory / "frame.exr", sample_image(), sample_metadata()),
                 std::runtime_error);
    EXPECT_EQ(names_in(directory), std::vector<std::string>{"frame.cost.png"});
    EXPECT_TRUE(std::filesystem::is_directory(directory / "frame.cost.png"));
}

TEST(ReadExr, ReportsAFileThatIsNotAnExr) {
    const auto directory = fresh_directory("exr_not_exr");
    {
        std::ofstream text(directory / "text.exr");
        text << "not an image";
    }
    EXPECT_THROW(read_exr(directory / "text.exr"), std::runtime_error);
    EXPECT_THROW(read_exr(directory / "missing.exr"), std::runtime_error);
}

std::uint32_t bits_of(float value) {
    std::uint32_t bits;
    std::memcpy(&bits, &value, sizeof(bits));
    return bits;
}

float float_of(std::uint32_t bits) {
    float value;
    std::memcpy(&value, &bits, sizeof(value));
    return value;
}

/// Every value of every channel from `random` bit patterns (NaNs, infinities and subnormals
/// among them: nothing a zip chunk could shorten), or one constant pixel (everything can).
Image chunk_test_image(int width, int height, bool noise, std::mt19937& random) {
    Image image(width, height);
    for (Pixel& pixel : image.pixels()) {
        for (float* channel : {&pixel.red, &pixel.green, &pixel.blue, &pixel.alpha, &pixel.depth,
                               &pixel.normal_x, &pixel.normal_y, &pixel.normal_z, &pixel.cost,
                               &pixel.cost_nodes, &pixel.cost_primitives, &pixel.cost_solves}) {
            *channel = noise ? float_of(random()) : 0.25f;
        }
        pixel.object_id = noise ? random() : 7u;
    }
    return image;
}

// The writer compresses EXR's ZIP chunks itself (16 lines each, the last one shorter) and
// stores a chunk uncompressed when zlib does not shorten it. Every channel reads back with
// OpenEXR's own reader as the pixel held it: the bits of each float and uint, and the colour
// as Imath's rounding to half gives it; for every size of last chunk and either kind of chunk.
TEST(WriteExr, EveryChunkReadsBackAsWrittenWhateverItsSizeOrContent) {
    const auto directory = fresh_directory("exr_chunks");
    std::mt19937 random(20261207);
    struct Size {
        int width;
        int height;
    };
    for (const Size size : {Size{1, 1}, Size{7, 17}, Size{33, 40}, Size{2, 16}}) {
        for (const bool noise : {true, false}) {
            SCOPED_TRACE(std::to_string(size.width) + "x" + std::to_string(size.height) +
                         (noise ? " noise" : " constant"));
            const Image image = chunk_test_image(size.width, size.height, noise, random);
            CostLayer layer;
            layer.structure = "grid";
            layer.width = size.width;
            layer.height = size.height;
            for (std::vector<float>* values :
                 {&layer.nodes, &layer.primitives, &layer.solves, &layer.total}) {
                for (std::size_t i = 0; i < image.pixel_count(); ++i) {
                    values->push_back(noise ? float_of(random()) : 3.0f);
                }
            }
            const auto path = directory / "chunks.exr";
            write_exr(path, image, sample_metadata(), std::span<const CostLayer>(&layer, 1));
            const ExrFile file = read_exr(path);
            ASSERT_EQ(file.image.pixel_count(), image.pixel_count());
            for (std::size_t i = 0; i < image.pixel_count(); ++i) {
                const Pixel& a = image.pixels()[i];
                const Pixel& b = file.image.pixels()[i];
                ASSERT_EQ(bits_of(b.red), bits_of(float(half(a.red)))) << i;
                ASSERT_EQ(bits_of(b.green), bits_of(float(half(a.green)))) << i;
                ASSERT_EQ(bits_of(b.blue), bits_of(float(half(a.blue)))) << i;
                ASSERT_EQ(bits_of(b.alpha), bits_of(float(half(a.alpha)))) << i;
                for (const auto member : {&Pixel::depth, &Pixel::normal_x, &Pixel::normal_y,
                                          &Pixel::normal_z, &Pixel::cost, &Pixel::cost_nodes,
                                          &Pixel::cost_primitives, &Pixel::cost_solves}) {
                    ASSERT_EQ(bits_of(b.*member), bits_of(a.*member)) << i;
                }
                ASSERT_EQ(b.object_id, a.object_id) << i;
            }
            ASSERT_EQ(file.cost_layers.size(), 1u);
            EXPECT_EQ(file.cost_layers[0].structure, "grid");
            const std::vector<float>* written[] = {&layer.nodes, &layer.primitives, &layer.solves,
                                                   &layer.total};
            const std::vector<float>* read[] = {
                &file.cost_layers[0].nodes, &file.cost_layers[0].primitives,
                &file.cost_layers[0].solves, &file.cost_layers[0].total};
            for (int c = 0; c < 4; ++c) {
                ASSERT_EQ(read[c]->size(), written[c]->size());
                for (std::size_t i = 0; i < written[c]->size(); ++i) {
                    ASSERT_EQ(bits_of((*read[c])[i]), bits_of((*written[c])[i])) << c << " " << i;
                }
            }
            // Noise is stored (the file holds at least its 54 bytes a pixel: 4 halves, 12
            // floats, a uint); a constant image zips to a small part of that.
            const auto bytes = std::filesystem::file_size(path);
            const auto raw = 54u * image.pixel_count();
            if (noise) {
                EXPECT_GE(bytes, raw);
            } else if (image.pixel_count() >= 64) {
                EXPECT_LT(bytes, raw / 2);
            }
        }
    }
}

// The colour channels are rounded to half as Imath's conversion rounds them, bit for bit, at
// every boundary of the format and for NaNs of every kind (a converter that quiets NaNs, as
// F16C's does, fails here).
TEST(WriteExr, ColourRoundsToHalfAsImathDoesAtEveryBoundary) {
    const std::vector<std::uint32_t> patterns = {
        0x00000000u, 0x80000000u,              // zeros
        0x477fe000u, 0x477fefffu, 0x477ff000u,  // 65504, just below and at the overflow tie
        0x501502f9u, 0x7f800000u, 0xff800000u,  // 1e10, infinities
        0x38800000u, 0x33800000u, 0x33000000u,  // smallest normal and subnormal half, the tie
        0x33400000u, 0x33c00000u, 0x387fc000u,  // 1.5 and 3 x 2^-25, largest subnormal
        0x3f801000u, 0x3f800800u, 0x3f801800u,  // 1 + 2^-10 exact, ties to even down and up
        0x000116c2u, 0x807fffffu,              // float subnormals
        0x7f800001u, 0x7fc00000u, 0x7fa00000u,  // signalling, quiet, payload-only NaNs
        0xffc00001u, 0x7f802000u, 0x7f801fffu,  // negative NaN, payloads at bit 13 and below
    };
    const int width = static_cast<int>(patterns.size());  // 25: three groups of 8 and a tail
    Image image(width, 2);
    for (int x = 0; x < width; ++x) {
        for (int y = 0; y < 2; ++y) {
            Pixel& pixel = image.at(x, y);
            pixel.red = float_of(patterns[x]);
            pixel.green = float_of(patterns[(x + y + 1) % width]);
            pixel.blue = -float_of(patterns[(x + 7) % width]);
            pixel.alpha = float_of(patterns[(3 * x + y) % width]);
        }
    }
    const auto directory = fresh_directory("exr_half_boundaries");
    write_exr(directory / "half.exr", image, sample_metadata());
    const ExrFile file = read_exr(directory / "half.exr");
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        const Pixel& a = image.pixels()[i];
        const Pixel& b = file.image.pixels()[i];
        ASSERT_EQ(half(b.red).bits(), half(a.red).bits()) << i;
        ASSERT_EQ(half(b.green).bits(), half(a.green).bits()) << i;
        ASSERT_EQ(half(b.blue).bits(), half(a.blue).bits()) << i;
        ASSERT_EQ(half(b.alpha).bits(), half(a.alpha).bits()) << i;
    }
}

TEST(WriteExr, TheFileDoesNotDependOnTheThreadCount) {
    const auto directory = fresh_directory("exr_threads");
    std::mt19937 random(7);
    Image image(300, 70);  // 5 chunks a part, the last of 6 lines
    for (Pixel& pixel : image.pixels()) {
        pixel.red = float(random() % 1000) / 999.0f;
        pixel.depth = float(random() % 5000) * 0.01f;
        pixel.object_id = random() % 3;
    }
    {
        const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        write_exr(directory / "one.exr", image, sample_metadata());
    }
    write_exr(directory / "all.exr", image, sample_metadata());
    EXPECT_EQ(test::file_contents(directory / "one.exr"),
              test::file_contents(directory / "all.exr"));
}

// OpenEXR 3.1's reader of the idManifest attribute reads 4 bytes past it, into the name of the
// attribute after it; the id part must still read whole (its chunkCount found), as before.
TEST(WriteExr, TheIdPartReadsWholeWithOpenExr31sReader) {
    const auto directory = fresh_directory("exr_id_part");
    std::mt19937 random(1);
    write_exr(directory / "out.exr", chunk_test_image(3, 40, false, random), sample_metadata());
    Imf::MultiPartInputFile file((directory / "out.exr").c_str());
    ASSERT_EQ(file.parts(), 2);
    for (int part = 0; part < 2; ++part) {
        ASSERT_TRUE(file.header(part).hasChunkCount()) << part;
        EXPECT_EQ(file.header(part).chunkCount(), 3) << part;  // 40 lines, 16 a chunk
        EXPECT_EQ(file.header(part).compression(), Imf::ZIP_COMPRESSION) << part;
    }
    EXPECT_TRUE(Imf::hasIDManifest(file.header(1)));
}

}  // namespace
}  // namespace csgrt
