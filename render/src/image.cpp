#include "csgrt/render/image.h"

#include "csgrt/core/error.h"

namespace csgrt {

Image::Image(int width, int height) : Image(width, height, true) {}

Image Image::for_writing(int width, int height) {
    return Image(width, height, false);
}

Image::Image(int width, int height, bool fill_defaults)
    : width_(width), height_(height), pixels_(PixelAllocator<Pixel>(fill_defaults)) {
    require(width > 0, "Image", "width", "> 0", width);
    require(height > 0, "Image", "height", "> 0", height);
    pixels_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
}

}  // namespace csgrt
