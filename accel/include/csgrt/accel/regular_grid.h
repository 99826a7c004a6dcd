#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/core/aabb.h"

namespace csgrt {

namespace detail {

/// The cells of one uniform grid: a box cut into resolution[0] x resolution[1] x resolution[2]
/// equal cells, numbered x fastest. Cell (i, j, k) spans lower + (i, j, k) * cell_size to
/// lower + (i + 1, j + 1, k + 1) * cell_size; the traversal and the build use these same
/// formulas, so they agree on every boundary.
struct GridGeometry {
    Aabb bounds;
    std::array<int, 3> resolution{0, 0, 0};
    Vector3 cell_size{0.0, 0.0, 0.0};
    /// 1 / cell_size, or 0 on an axis with one cell of zero extent.
    Vector3 inverse_cell_size{0.0, 0.0, 0.0};

    std::size_t cell_count() const {
        return std::size_t(resolution[0]) * std::size_t(resolution[1]) * std::size_t(resolution[2]);
    }
    std::size_t cell_index(int x, int y, int z) const {
        return (std::size_t(z) * std::size_t(resolution[1]) + std::size_t(y)) *
                   std::size_t(resolution[0]) +
               std::size_t(x);
    }
    /// The cell coordinate of position p along `axis`, clamped into [0, resolution - 1] (so
    /// points on or outside the faces belong to the outer cells; NaN gives 0).
    int cell_coordinate(double p, int axis) const {
        const double f = (p - bounds.lower[axis]) * inverse_cell_size[axis];
        // Compared in double before converting, so out-of-range values never overflow the int.
        if (!(f >= 1.0)) return 0;
        if (f >= double(resolution[axis])) return resolution[axis] - 1;
        return static_cast<int>(f);
    }
    Aabb cell_box(int x, int y, int z) const;
};

/// The geometry of a grid over `bounds` for `count` primitives: the cell edge a comes from
/// the density heuristic over the axes of non-zero extent (a = (measure / cells)^(1/k) with k
/// such axes), each such axis gets clamp(round(extent / a), 1, max_resolution) cells, a
/// flat axis gets one. Axes that round to one cell are fixed at one and a is recomputed over
/// the rest, so nearly flat scenes get the cells they should.
GridGeometry choose_grid_geometry(const Aabb& bounds, std::size_t count, double cells_per_primitive,
                                  int max_resolution);

}  // namespace detail

/// A uniform grid over a primitive set: the scene box cut into equal cells, each listing the
/// primitives that overlap it, in compact (CSR) form: one offset per cell into one array of
/// primitive indices. Rays walk the cells they cross in order with the 3D-DDA of Amanatides &
/// Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing", Eurographics 1987, and stop at the
/// first cell that ends beyond the nearest hit found. A per-ray hashed mailbox on the stack
/// skips most repeated tests of primitives that span several cells and keeps queries
/// thread-safe. Primitives with unbounded or empty boxes are tested by every ray.
template <class Set>
class RegularGrid final : public AcceleratorBase<RegularGrid<Set>, Set> {
public:
    void build(const Set& set, const GridConfig& config = {});

    static constexpr std::string_view kName = "grid";
    /// Every query (the Accelerator overrides come from AcceleratorBase).
    template <QueryKind kKind, bool kCounted>
    bool query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
               TraversalCounters& counters) const;

    /// The grid's cells (box, resolution, cell size), for tests and reports.
    const detail::GridGeometry& geometry() const { return geometry_; }
    /// The primitives listed in cell (x, y, z), in ascending index order.
    std::span<const std::uint32_t> cell_primitives(int x, int y, int z) const;
    /// The Chebyshev distance, in cells and capped at 16, from cell (x, y, z) to the nearest
    /// cell with primitives (0 for those): the walk jumps over the empty cells within that
    /// distance minus one.
    int empty_radius(int x, int y, int z) const {
        return empty_radius_[geometry_.cell_index(x, y, z)];
    }
    /// Primitives every ray tests because their boxes are unbounded or empty.
    std::span<const std::uint32_t> unbounded_primitives() const { return unbounded_; }

private:
    /// The unbounded primitives, then the cells along the ray (detail::grid_query's walk).
    template <class Visitor>
    bool walk(const Ray& ray, Visitor& visitor) const;
    using AcceleratorBase<RegularGrid<Set>, Set>::stats_;
    bool is_occupied(std::size_t cell) const { return (occupied_[cell / 64] >> (cell % 64)) & 1; }

    const Set* set_ = nullptr;
    detail::GridGeometry geometry_;
    /// A scale of the scene's coordinates (largest |coordinate| plus largest extent), which the
    /// stopping margin is relative to.
    double scene_scale_ = 0.0;
    /// Cell c lists primitives_[offsets_[c] .. offsets_[c + 1]).
    std::vector<std::uint32_t> offsets_;
    std::vector<std::uint32_t> primitives_;
    /// One bit per cell, set when its list is not empty: most cells of a mesh's grid are
    /// empty, and this 32 times smaller array stays in cache while the rays cross them.
    std::vector<std::uint64_t> occupied_;
    /// Per cell, the Chebyshev distance (in cells, capped at 16) to the nearest occupied
    /// cell: the walk jumps over the empty cells around a cell in one step.
    std::vector<std::uint8_t> empty_radius_;
    std::vector<std::uint32_t> unbounded_;
};

extern template class RegularGrid<TriangleSet<float>>;
extern template class RegularGrid<TriangleSet<double>>;
extern template class RegularGrid<ShapeSet>;

}  // namespace csgrt
