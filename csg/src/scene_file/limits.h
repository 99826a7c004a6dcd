#pragma once

// The limits docs/scene-format.md ("Limits") documents, in one place for every part of the
// loader.

#include <cstddef>
#include <cstdint>
#include <limits>

namespace csgrt::detail::scene_file {

/// At most this many copies from one grid: a typo in a count must not exhaust memory.
constexpr std::size_t kMaxGridCopies = 1'000'000;

/// The limits docs/scene-format.md ("Limits") documents. Nesting: JSON arrays and objects, and
/// shapes inside shapes (booleans, compounds, grids, refs), so that a hostile file gives an
/// error instead of overflowing the stack in the loader or, later, in the queries.
constexpr std::size_t kMaxJsonDepth = 1000;
constexpr std::size_t kMaxShapeDepth = 256;
/// Leaf shapes in the expanded scene (every grid copy and every use of a definition counted):
/// shared definitions and nested grids describe 2^64 leaves in 5 KB, and a ray may have to
/// visit every one of them.
constexpr std::uint64_t kMaxExpandedLeaves = 10'000'000;
/// Leaf shapes overlapping at one point (overlapping_leaves): a ray there tests each of them,
/// whatever the structure, so a pile of 2^20 copies a nanometre apart never finishes a render.
constexpr std::uint64_t kMaxOverlappingLeaves = 10'000;
/// The file is parsed into memory whole; its tree takes about ten times its size.
constexpr std::uintmax_t kMaxSceneFileBytes = 256u << 20;
/// JSON values (numbers, strings, booleans, nulls, arrays, objects) in the file: each costs 16
/// bytes or more in the tree, so 256 MiB of "0," (2 bytes a value) built a tree of 4.6 GB;
/// at the limit such a file peaks at 1.3 GB with its text. 10^6 spheres are 7 * 10^6 values.
constexpr std::size_t kMaxJsonValues = std::size_t{1} << 25;
/// Keys and names longer than this are cut in messages.
constexpr std::size_t kLongestShownName = 64;
/// Lights, positions and distances: their squares must stay finite in the shading.
constexpr double kMaxLength = 1e150;
/// Light intensities and radiances: far below float's 3.4e38, where the image's pixels live.
constexpr double kMaxIntensity = 1e30;

/// `value` plus `add`, saturating at the largest count rather than wrapping.
inline std::uint64_t saturating_add(std::uint64_t value, std::uint64_t add) {
    return add > std::numeric_limits<std::uint64_t>::max() - value
               ? std::numeric_limits<std::uint64_t>::max()
               : value + add;
}

}  // namespace csgrt::detail::scene_file
