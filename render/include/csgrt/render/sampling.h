#pragma once

#include <cstdint>

#include "csgrt/core/math.h"

namespace csgrt {

/// SplitMix64 (Steele, Lea and Flood, "Fast Splittable Pseudorandom Number Generators", OOPSLA
/// 2014): the increment of its state, 2^64 over the golden ratio, and its output function, a
/// bijective mix of 64 bits (also used to hash seeds).
inline constexpr std::uint64_t kSplitMixIncrement = 0x9e3779b97f4a7c15ull;
inline std::uint64_t splitmix_mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/// A small random generator whose sequence is the same on every platform and compiler (the
/// std distributions are not): SplitMix64.
class SampleRandom {
public:
    explicit SampleRandom(std::uint64_t seed) : state_(seed) {}

    std::uint64_t next_bits() { return splitmix_mix(state_ += kSplitMixIncrement); }

    /// Uniform in [0, 1): the top 53 bits scaled by 2^-53, so 1 is never returned.
    double uniform() { return static_cast<double>(next_bits() >> 11) * 0x1.0p-53; }

private:
    std::uint64_t state_;
};

/// The random stream of pixel (x, y) of an image rendered with `seed`: depends on nothing
/// else, so a pixel's samples are the same whichever thread renders it and in whatever order.
SampleRandom pixel_random(std::uint64_t seed, int x, int y);

/// How `samples` samples are laid out in a pixel: a columns x rows grid of equal strata with
/// columns * rows == samples, rows the largest divisor of `samples` not above its square root
/// (so a perfect square N gives sqrt(N) x sqrt(N); 8 gives 4 x 2; a prime p gives p x 1).
struct StrataGrid {
    int columns = 1;
    int rows = 1;
};

/// Throws InvalidParameter unless samples >= 1.
StrataGrid strata_for(int samples);

/// Sample `index` (0 <= index < columns * rows) of a pixel: a uniform point in stratum
/// (index % columns, index / columns), as offsets in [0, 1)^2 from the pixel's top-left corner.
Vector2 stratified_sample(const StrataGrid& grid, int index, SampleRandom& random);

}  // namespace csgrt
