#include "csgrt/render/png.h"

#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace csgrt {

namespace {

void write_rgb8(const std::filesystem::path& path, int width, int height,
                const std::vector<std::uint8_t>& rgb) {
    png_image image;
    std::memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    image.width = static_cast<png_uint_32>(width);
    image.height = static_cast<png_uint_32>(height);
    image.format = PNG_FORMAT_RGB;
    // 8-bit formats of libpng's simplified API are sRGB-encoded, which is what we store.
    if (!png_image_write_to_file(&image, path.c_str(), 0, rgb.data(), 0, nullptr)) {
        const std::string message = image.message;
        png_image_free(&image);
        throw std::runtime_error("cannot write PNG '" + path.string() + "': " + message);
    }
}

}  // namespace

std::uint8_t encode_srgb8(double linear) {
    // NaN-safe clamp: a NaN becomes 0.
    const double c = linear > 0.0 ? std::min(linear, 1.0) : 0.0;
    const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(std::clamp(encoded, 0.0, 1.0) * 255.0));
}

Vector3 viridis(double t) {
    // Horner form of the degree-6 minimax fit; coefficients by Matt Zucker
    // (https://www.shadertoy.com/view/WlfXRN, CC0), fitted to matplotlib's table.
    static const std::array<Vector3, 7> kCoefficients = {
        Vector3(0.2777273272234177, 0.005407344544966578, 0.3340998053353061),
        Vector3(0.1050930431085774, 1.404613529898575, 1.384590162594685),
        Vector3(-0.3308618287255563, 0.214847559468213, 0.09509516302823659),
        Vector3(-4.634230498983486, -5.799100973351585, -19.33244095627987),
        Vector3(6.228269936347081, 14.17993336680509, 56.69055260068105),
        Vector3(4.776384997670288, -13.74514537774601, -65.35303263337234),
        Vector3(-5.435455855934631, 4.645852612178535, 26.3124352495832),
    };
    const double x = t > 0.0 ? std::min(t, 1.0) : 0.0;
    Vector3 value = kCoefficients[6];
    for (int k = 5; k >= 0; --k) value = kCoefficients[k] + x * value;
    return value.cwiseMax(0.0).cwiseMin(1.0);
}

void write_colour_png(const std::filesystem::path& path, const Image& image) {
    std::vector<std::uint8_t> rgb;
    rgb.reserve(3 * image.pixel_count());
    for (const Pixel& pixel : image.pixels()) {
        rgb.push_back(encode_srgb8(pixel.red));
        rgb.push_back(encode_srgb8(pixel.green));
        rgb.push_back(encode_srgb8(pixel.blue));
    }
    write_rgb8(path, image.width(), image.height(), rgb);
}

void write_cost_png(const std::filesystem::path& path, const Image& image) {
    float max_cost = 0.0f;
    for (const Pixel& pixel : image.pixels()) max_cost = std::max(max_cost, pixel.cost);
    std::vector<std::uint8_t> rgb;
    rgb.reserve(3 * image.pixel_count());
    for (const Pixel& pixel : image.pixels()) {
        const double t = max_cost > 0.0f ? double(pixel.cost) / max_cost : 0.0;
        const Vector3 colour = viridis(t);
        for (int channel = 0; channel < 3; ++channel) {
            rgb.push_back(static_cast<std::uint8_t>(std::lround(colour[channel] * 255.0)));
        }
    }
    write_rgb8(path, image.width(), image.height(), rgb);
}

}  // namespace csgrt
