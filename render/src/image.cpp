#include "csgrt/render/image.h"

#include <sys/mman.h>

#include <cstdlib>
#include <new>

#include "csgrt/core/error.h"

namespace csgrt {

namespace {

constexpr std::size_t kHugePage = std::size_t(1) << 21;

}  // namespace

void* allocate_pixel_memory(std::size_t bytes) {
    if (bytes < kHugePage) return ::operator new(bytes);
    // aligned_alloc wants a multiple of the alignment.
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* pointer = std::aligned_alloc(kHugePage, rounded);
    if (pointer == nullptr) throw std::bad_alloc();
    // Advice only: where huge pages are off or unavailable this fails and 4 KiB pages serve.
    static_cast<void>(::madvise(pointer, rounded, MADV_HUGEPAGE));
    return pointer;
}

void free_pixel_memory(void* pointer, std::size_t bytes) {
    if (bytes < kHugePage) {
        ::operator delete(pointer);
    } else {
        std::free(pointer);
    }
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
