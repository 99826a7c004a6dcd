#include "csgrt/render/sampling.h"

#include <algorithm>

#include "csgrt/core/error.h"

namespace csgrt {

namespace {
/// SplitMix64's output function: a bijective mix of 64 bits, used to hash seeds.
std::uint64_t mix_bits(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}
}  // namespace

SampleRandom pixel_random(std::uint64_t seed, int x, int y) {
    // Two rounds of mixing so neighbouring pixels and neighbouring seeds get unrelated streams.
    const std::uint64_t pixel = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(y)) << 32) |
                                static_cast<std::uint32_t>(x);
    return SampleRandom(mix_bits(mix_bits(pixel) ^ (seed + 0x9e3779b97f4a7c15ull)));
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
