#include "csgrt/accel/regular_grid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "accelerator_base.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"
#include "grid_common.h"

namespace csgrt {

namespace detail {

Aabb GridGeometry::cell_box(int x, int y, int z) const {
    const Vector3 lo(x, y, z), hi(x + 1, y + 1, z + 1);
    return Aabb(bounds.lower + lo.cwiseProduct(cell_size),
                bounds.lower + hi.cwiseProduct(cell_size));
}

GridGeometry choose_grid_geometry(const Aabb& bounds, std::size_t count, double cells_per_primitive,
                                  int max_resolution) {
    GridGeometry grid;
    grid.bounds = bounds;
    const Vector3 extent = bounds.diagonal();
    const double target_cells = std::max(1.0, cells_per_primitive * double(count));
    std::array<bool, 3> free{extent.x() > 0.0, extent.y() > 0.0, extent.z() > 0.0};
    grid.resolution = {1, 1, 1};
    // Axes that would get fewer than one cell are fixed at one and the cell edge is chosen
    // again over the others, so a flat or nearly flat scene spreads its cells over its plane.
    for (int round = 0; round < 3; ++round) {
        int dimensions = 0;
        double measure = 1.0;
        for (int axis = 0; axis < 3; ++axis) {
            if (!free[axis]) continue;
            ++dimensions;
            measure *= extent[axis];
        }
        if (dimensions == 0) break;
        const double edge = std::pow(measure / target_cells, 1.0 / dimensions);
        bool fixed_one = false;
        for (int axis = 0; axis < 3; ++axis) {
            if (!free[axis]) continue;
            const double cells = std::round(extent[axis] / edge);
            if (!(cells >= 1.0)) {
                free[axis] = false;
                grid.resolution[axis] = 1;
                fixed_one = true;
            } else {
                grid.resolution[axis] = int(std::min(cells, double(max_resolution)));
            }
        }
        if (!fixed_one) break;
    }
    for (int axis = 0; axis < 3; ++axis) {
        grid.cell_size[axis] = extent[axis] / grid.resolution[axis];
        grid.inverse_cell_size[axis] =
            grid.cell_size[axis] > 0.0 ? 1.0 / grid.cell_size[axis] : 0.0;
    }
    return grid;
}

}  // namespace detail

namespace {

/// Distances beyond this many cells are recorded as this many (they fit a byte, and longer
/// jumps are rare).
constexpr int kRadiusCap = 16;

/// One pass of the separable Chebyshev distance transform along a line of `count` cells
/// `stride` apart: g(j) = min over j' of max(|j - j'|, f(j')), with f capped at kRadiusCap so
/// only |j - j'| < kRadiusCap matters. (The L-infinity distance to the nearest occupied
/// cell is the min over occupied cells of the max of the three per-axis distances, so
/// taking the 1D distance along x and then this pass along y and along z gives it exactly.)
void chebyshev_pass(std::uint8_t* line, int count, std::ptrdiff_t stride,
                    std::vector<std::uint8_t>& buffer) {
    buffer.resize(std::size_t(count));
    for (int j = 0; j < count; ++j) buffer[std::size_t(j)] = line[j * stride];
    for (int j = 0; j < count; ++j) {
        int best = buffer[std::size_t(j)];
        for (int offset = 1; offset < best; ++offset) {
            if (j - offset >= 0)
                best = std::min(best, std::max(offset, int(buffer[std::size_t(j - offset)])));
            if (j + offset < count)
                best = std::min(best, std::max(offset, int(buffer[std::size_t(j + offset)])));
        }
        line[j * stride] = std::uint8_t(best);
    }
}

/// For every cell, the Chebyshev distance in cells to the nearest cell with a non-empty list
/// (0 for those), capped at kRadiusCap: a cell at distance r has only empty cells within
/// distance r - 1, which the walk may jump over.
std::vector<std::uint8_t> empty_radii(const detail::GridGeometry& grid,
                                      const std::vector<std::uint32_t>& offsets) {
    const int nx = grid.resolution[0], ny = grid.resolution[1], nz = grid.resolution[2];
    std::vector<std::uint8_t> radius(grid.cell_count(), std::uint8_t(kRadiusCap));
    // Along x: the distance to the nearest occupied cell of the row, from both sides.
    for (int z = 0; z < nz; ++z) {
        for (int y = 0; y < ny; ++y) {
            std::uint8_t* row = &radius[grid.cell_index(0, y, z)];
            const std::uint32_t* row_offsets = &offsets[grid.cell_index(0, y, z)];
            int distance = kRadiusCap;
            for (int x = 0; x < nx; ++x) {
                distance =
                    row_offsets[x] != row_offsets[x + 1] ? 0 : std::min(distance + 1, kRadiusCap);
                row[x] = std::uint8_t(distance);
            }
            distance = kRadiusCap;
            for (int x = nx - 1; x >= 0; --x) {
                distance = row[x] == 0 ? 0 : std::min(distance + 1, kRadiusCap);
                row[x] = std::uint8_t(std::min<int>(row[x], distance));
            }
        }
    }
    std::vector<std::uint8_t> buffer;
    for (int z = 0; z < nz; ++z) {
        for (int x = 0; x < nx; ++x)
            chebyshev_pass(&radius[grid.cell_index(x, 0, z)], ny, nx, buffer);
    }
    for (int y = 0; y < ny; ++y) {
        for (int x = 0; x < nx; ++x)
            chebyshev_pass(&radius[grid.cell_index(x, y, 0)], nz, std::ptrdiff_t(nx) * ny, buffer);
    }
    return radius;
}

}  // namespace

template <class Set>
void RegularGrid<Set>::build(const Set& set, const GridConfig& config) {
    require(config.cells_per_primitive > 0.0 && std::isfinite(config.cells_per_primitive),
            "RegularGrid", "cells_per_primitive", "> 0 and finite", config.cells_per_primitive);
    require(config.max_resolution >= 1 && config.max_resolution <= 4096, "RegularGrid",
            "max_resolution", "in [1, 4096]", config.max_resolution);
    const auto start = std::chrono::steady_clock::now();
    set_ = &set;
    offsets_.clear();
    primitives_.clear();
    unbounded_.clear();
    std::vector<std::uint32_t> bounded;
    const Aabb bounds = detail::grid_bounds(set, bounded, unbounded_, scene_scale_);
    geometry_ = detail::GridGeometry{};
    if (!bounded.empty()) {
        geometry_ = detail::choose_grid_geometry(bounds, bounded.size(), config.cells_per_primitive,
                                                 config.max_resolution);
        detail::fill_cells(set, bounded, geometry_, scene_scale_, config.triangle_box_test,
                           offsets_, primitives_);
    }
    empty_radius_ =
        bounded.empty() ? std::vector<std::uint8_t>{} : empty_radii(geometry_, offsets_);
    occupied_.assign((geometry_.cell_count() + 63) / 64, 0);
    for (std::size_t c = 0; c < geometry_.cell_count(); ++c) {
        if (offsets_[c] != offsets_[c + 1]) occupied_[c / 64] |= std::uint64_t(1) << (c % 64);
    }
    offsets_.shrink_to_fit();
    primitives_.shrink_to_fit();
    unbounded_.shrink_to_fit();

    stats_ = AcceleratorStats{};
    stats_.name = "grid";
    stats_.primitives = set.size();
    stats_.nodes = geometry_.cell_count();
    stats_.references = primitives_.size() + unbounded_.size();
    stats_.bytes = (offsets_.capacity() + primitives_.capacity() + unbounded_.capacity()) *
                       sizeof(std::uint32_t) +
                   occupied_.capacity() * sizeof(std::uint64_t) + empty_radius_.capacity();
    std::size_t empty = 0;
    for (std::size_t c = 0; c < geometry_.cell_count(); ++c)
        empty += offsets_[c] == offsets_[c + 1];
    std::ostringstream details;
    details.precision(3);
    details << "resolution " << geometry_.resolution[0] << "x" << geometry_.resolution[1] << "x"
            << geometry_.resolution[2] << ", "
            << (bounded.empty() ? 0.0 : double(primitives_.size()) / double(bounded.size()))
            << " references per primitive, "
            << (stats_.nodes ? 100.0 * double(empty) / double(stats_.nodes) : 0.0)
            << "% empty cells, " << unbounded_.size() << " unbounded";
    stats_.details = details.str();
    stats_.build_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
std::span<const std::uint32_t> RegularGrid<Set>::cell_primitives(int x, int y, int z) const {
    const std::size_t cell = geometry_.cell_index(x, y, z);
    return std::span<const std::uint32_t>(primitives_)
        .subspan(offsets_[cell], offsets_[cell + 1] - offsets_[cell]);
}

template <class Set>
template <class Visitor>
bool RegularGrid<Set>::walk(const Ray& ray, Visitor& visitor) const {
    // Every ray tests the unbounded primitives; no cell lists them, so no mailbox is needed.
    for (const std::uint32_t primitive : unbounded_) {
        if (visitor.test(primitive)) return true;
    }
    const Vector3 inverse_direction = ray.direction.cwiseInverse();
    double t_enter, t_exit;
    visitor.count_box();
    if (primitives_.empty() ||
        !detail::clip_to_box(geometry_.bounds, ray, inverse_direction, t_enter, t_exit))
        return false;
    bool stop = false;
    detail::walk_cells(
        geometry_, ray, inverse_direction, t_enter, t_exit,
        [&](std::size_t cell, double cell_exit) {
            visitor.count_cell();
            if (!is_occupied(cell)) return false;
            const std::span<const std::uint32_t> list(primitives_.data() + offsets_[cell],
                                                      offsets_[cell + 1] - offsets_[cell]);
            return stop = visitor.leaf(list) || visitor.done(cell_exit);
        },
        [&](std::size_t cell) { return int(empty_radius_[cell]); });
    return stop;
}

template <class Set>
template <QueryKind kKind, bool kCounted>
bool RegularGrid<Set>::query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
                             TraversalCounters& counters) const {
    return detail::grid_query<kKind, kCounted>(set_, scene_scale_, ray, answer, scratch, counters,
                                               [&](auto& visitor) { return walk(ray, visitor); });
}

template class RegularGrid<TriangleSet<float>>;
template class RegularGrid<TriangleSet<double>>;
template class RegularGrid<ShapeSet>;

}  // namespace csgrt

CSGRT_INSTANTIATE_ACCELERATOR_BASE(csgrt::RegularGrid);
