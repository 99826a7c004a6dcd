#include "csgrt/render/sampling.h"

#include <algorithm>

#include "csgrt/core/error.h"

namespace csgrt {

SampleRandom pixel_random(std::uint64_t seed, int x, int y) {
    // Two rounds of mixing so neighbouring pixels and neighbouring seeds get unrelated streams.
    const std::uint64_t pixel = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(y)) << 32) |
                                static_cast<std::uint32_t>(x);
    return SampleRandom(splitmix_mix(splitmix_mix(pixel) ^ (seed + kSplitMixIncrement)));
}

StrataGrid strata_for(int samples) {
    require(samples >= 1, "strata_for", "samples", ">= 1", samples);
    int rows = 1;
    for (int divisor = 1; divisor * divisor <= samples; ++divisor) {
        if (samples % divisor == 0) rows = divisor;
    }
    return StrataGrid{samples / rows, rows};
}

Vector2 stratified_sample(const StrataGrid& grid, int index, SampleRandom& random) {
    const int column = index % grid.columns;
    const int row = index / grid.columns;
    const double jitter_x = random.uniform();
    const double jitter_y = random.uniform();
    // (column + jitter) / columns < 1 for jitter < 1, except where rounding lands on 1 exactly.
    return Vector2(std::min((column + jitter_x) / grid.columns, next_down(1.0)),
                   std::min((row + jitter_y) / grid.rows, next_down(1.0)));
}

}  // namespace csgrt
