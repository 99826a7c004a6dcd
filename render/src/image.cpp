#include "csgrt/render/image.h"

#include "csgrt/core/error.h"

namespace csgrt {

Image::Image(int width, int height) : width_(width), height_(height) {
    require(width > 0, "Image", "width", "> 0", width);
    require(height > 0, "Image", "height", "> 0", height);
    pixels_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
}

}  // namespace csgrt
