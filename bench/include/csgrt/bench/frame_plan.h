#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace csgrt::bench {

/// How a CSG scene's frame is timed: rendered at `width` x `width` pixels, and the time
/// multiplied by `scale` to stand for the requested frame.
struct FramePlan {
    int width = 0;
    double scale = 1.0;
    bool extrapolated() const { return scale != 1.0; }
};

/// The frame to render for a requested `width` x `width` frame when every ray tests
/// `tests_per_ray` objects (brute force: all of them) and a pixel casts `rays_per_pixel` rays
/// (the primary ray and one shadow ray a light): the full frame when its object tests fit in
/// `budget`, otherwise the largest square frame, at least `min_width` wide, that fits, with
/// `scale` = requested pixels / rendered pixels. The smaller frame shows the same view, so its
/// rays cover the whole image and the time per pixel carries over.
inline FramePlan plan_frame(int width, double tests_per_ray, double rays_per_pixel, double budget,
                            int min_width = 16) {
    FramePlan plan{width, 1.0};
    const double pixels = static_cast<double>(width) * width;
    const double tests = pixels * std::max(1.0, rays_per_pixel) * std::max(1.0, tests_per_ray);
    if (!(tests > budget) || width <= min_width) return plan;
    const double fitting = std::floor(static_cast<double>(width) * std::sqrt(budget / tests));
    plan.width = std::clamp(static_cast<int>(fitting), min_width, width);
    plan.scale = pixels / (static_cast<double>(plan.width) * plan.width);
    return plan;
}

}  // namespace csgrt::bench
