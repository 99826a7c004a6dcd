#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace csgrt::detail {

/// Splits a polygon into triangles in the plane of its Newell normal, keeping its winding:
/// EarClipper's ear clipping, which keeps repeated corners, so a face written as a keyhole
/// (a hole joined to the outer loop by a bridge) keeps its hole. Returns false when the
/// polygon was not simple: its edges cross (a crossing was cut off) or it collapses, or
/// corners were left that no ear could take and were fanned. Its triangles' area may then
/// differ from the polygon's; the fan's degenerate triangles are dropped by validation.
bool triangulate(std::span<const std::uint32_t> polygon,
                 const std::vector<Eigen::Vector3d>& vertices,
                 std::vector<std::array<std::uint32_t, 3>>& triangles);

}  // namespace csgrt::detail
