#include "csgrt/render/image.h"

#include <new>

#include "csgrt/core/error.h"

namespace csgrt {

void* allocate_pixel_memory(std::size_t bytes) {
    return ::operator new(bytes);
}

void free_pixel_memory(void* pointer, std::size_t /*bytes*/) {
    ::operator delete(pointer);
}

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
