#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "csgrt/core/math.h"

namespace csgrt {

/// Everything the renderer knows about one pixel. Colour is linear RGB, premultiplied by
/// alpha (the background is transparent black). The other channels (AOVs) come from one ray
/// through the pixel centre: depth is its t (the camera's rays have unit directions, so t is
/// the distance from the camera origin; +inf where nothing is hit), normal is the world-space
/// shading normal of the surface as the surface defines it (outward for solids, not turned
/// toward the camera; zero for background), object_id the scene object (kNoIndex for
/// background) and the cost channels the work that ray caused at every level of the scene.
struct Pixel {
    float red = 0.0f;
    float green = 0.0f;
    float blue = 0.0f;
    float alpha = 0.0f;
    float depth = std::numeric_limits<float>::infinity();
    float normal_x = 0.0f;
    float normal_y = 0.0f;
    float normal_z = 0.0f;
    std::uint32_t object_id = kNoIndex;
    /// The centre ray's work at every level (core/query_cost.h): box tests (structure nodes
    /// or cells visited, CSG and compound bounding boxes), primitive tests, leaf root solves,
    /// and `cost` their sum. Counts, exact as float up to 2^24.
    float cost = 0.0f;
    float cost_nodes = 0.0f;
    float cost_primitives = 0.0f;
    float cost_solves = 0.0f;
};

/// With `fill_defaults` false, a new element is left as the memory holds it (Pixel is an
/// aggregate, so its object exists there: C++20's implicit-lifetime rule) for an owner that
/// writes every element before it reads one; copies are made as always.
template <class T>
struct PixelAllocator {
    using value_type = T;
    bool fill_defaults = true;

    PixelAllocator() = default;
    explicit PixelAllocator(bool fill) : fill_defaults(fill) {}
    template <class U>
    PixelAllocator(const PixelAllocator<U>& other) : fill_defaults(other.fill_defaults) {}

    // operator new's memory, in pages of 4 KiB. Transparent huge pages (asked for here from
    // 2026-12-02 to 2026-12-07) fault a 2048^2 image (218 MB) in about 100 pieces rather than
    // 53,000, but on this project's machines (Firecracker guests that report free 8 MiB blocks
    // to the host, which takes them back) a fresh huge page costs the host's refault of all of
    // it: an empty 2048^2 frame on one thread took 0.44-0.67 s with them and 0.17-0.19 s
    // without (docs/benchmarks.md, "The image's pages").
    T* allocate(std::size_t count) { return static_cast<T*>(::operator new(count * sizeof(T))); }
    void deallocate(T* pointer, std::size_t) { ::operator delete(pointer); }

    template <class U, class... Args>
    void construct(U* pointer, Args&&... args) {
        if constexpr (sizeof...(Args) == 0) {
            if (!fill_defaults) return;
        }
        ::new (static_cast<void*>(pointer)) U(std::forward<Args>(args)...);
    }
    /// A copy of an image fills the elements it adds later; a moved-into one keeps the
    /// choice of the image it took the pixels from.
    PixelAllocator select_on_container_copy_construction() const { return PixelAllocator(); }
    using propagate_on_container_move_assignment = std::true_type;

    template <class U>
    bool operator==(const PixelAllocator<U>&) const {
        return true;
    }
};

/// A rendered image: width x height pixels, row-major from the top-left corner.
class Image {
public:
    Image() = default;
    /// Throws InvalidParameter unless width and height are positive. Every pixel starts as
    /// Pixel's defaults (the background).
    Image(int width, int height);
    /// An image whose pixels the caller writes, every one, before reading any (the
    /// renderer). They are not filled first: filling wrote a 2048^2 frame's 218 MB once more
    /// and on one thread, where the render's threads now touch each page first, in parallel.
    static Image for_writing(int width, int height);

    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t pixel_count() const { return pixels_.size(); }

    Pixel& at(int x, int y) { return pixels_[index(x, y)]; }
    const Pixel& at(int x, int y) const { return pixels_[index(x, y)]; }
    using Pixels = std::vector<Pixel, PixelAllocator<Pixel>>;
    Pixels& pixels() { return pixels_; }
    const Pixels& pixels() const { return pixels_; }

private:
    Image(int width, int height, bool fill_defaults);

    std::size_t index(int x, int y) const {
        return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
               static_cast<std::size_t>(x);
    }

    int width_ = 0;
    int height_ = 0;
    Pixels pixels_;
};

/// The cost channels of one render of a scene whose every structure is one kind
/// (`csgrt render --cost-all`, docs/rendering.md): per pixel, row-major from the top-left
/// corner, the centre ray's box tests, primitive tests, root solves and their total, as in
/// Pixel.
struct CostLayer {
    /// The factory name of the structure every level of the scene was built with.
    std::string structure;
    /// The build times of every structure in that scene (the top level's, each compound's and
    /// each mesh's), summed: the time in their build(). Ray classification splits its cells
    /// as rays reach them, so for it this is the clusters and the six root cells only; the
    /// splitting is inside trace_milliseconds.
    double build_milliseconds = 0.0;
    /// The wall time of tracing and counting the layer's centre rays (with every lazy build
    /// the rays caused).
    double trace_milliseconds = 0.0;
    int width = 0;
    int height = 0;
    std::vector<float> nodes;
    std::vector<float> primitives;
    std::vector<float> solves;
    std::vector<float> total;
};

}  // namespace csgrt
