#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/accel/regular_grid.h"

namespace csgrt {

/// A hierarchy of uniform grids after Jevans & Wyvill, "Adaptive Voxel Subdivision for Ray
/// Tracing", Graphics Interface 1989: a coarse top grid (N^0.6 cells, Ize et al. 2007) whose
/// crowded cells hold grids of their own, recursively. Unlike Klimaszewski & Sederberg, "Faster
/// Ray Tracing Using Adaptive Grids", IEEE CG&A 1997, it does not search for uniform regions
/// spanning several cells: each cell decides alone. A cell gets a sub-grid only when the
/// sub-grid separates its primitives (no sub-cell lists them all, few references per
/// primitive) and an estimate of a random ray's cost says it pays: cells it would visit plus
/// primitives it would test, each weighted by the chance that a ray crossing the cell crosses the
/// sub-cell (the ratio of surface areas), against testing the cell's list. So cells of identical or
/// huge primitives stay lists. Each sub-grid is built from its cell's list (not from the whole set)
/// over the cell's box shrunk to the primitives in it. Traversal runs the regular grid's DDA at
/// every level, descending into sub-grids, with one mailbox and one stopping rule for the whole
/// ray.
template <class Set>
class HierarchicalGrid final : public AcceleratorBase<HierarchicalGrid<Set>, Set> {
public:
    void build(const Set& set, const HierarchicalGridConfig& config = {});

    static constexpr std::string_view kName = "hgrid";
    /// Every query (the Accelerator overrides come from AcceleratorBase).
    template <QueryKind kKind, bool kCounted>
    bool query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
               TraversalCounters& counters) const;

    /// Number of grids (the top grid is grid 0).
    std::size_t grid_count() const { return grids_.size(); }
    /// The cells of grid `grid`.
    const detail::GridGeometry& geometry(std::size_t grid) const { return grids_[grid].geometry; }
    /// Deepest nesting built (0: only the top grid).
    int depth() const { return depth_; }
    /// The list of the innermost cell holding point p (empty outside every grid): what a ray
    /// through p tests there. For tests and reports.
    std::span<const std::uint32_t> primitives_at(const Point3& p) const;

private:
    /// One uniform grid of the hierarchy; its cells are cells_[first_cell ..].
    struct Grid {
        detail::GridGeometry geometry;
        std::uint32_t first_cell;
    };
    /// A list of primitives_[begin .. begin + count), or (count == kSubGrid) the grid
    /// grids_[begin].
    struct Cell {
        std::uint32_t begin;
        std::uint32_t count;
    };
    static constexpr std::uint32_t kSubGrid = 0xffffffffu;

    /// Appends a grid with the given cells and CSR lists, refining crowded cells; returns its
    /// index.
    std::uint32_t add_grid(const Set& set, const detail::GridGeometry& geometry,
                           const std::vector<std::uint32_t>& offsets,
                           const std::vector<std::uint32_t>& lists, int depth);
    /// Walks grid `grid` and its sub-grids along the ray; true when the visitor asked to stop.
    template <class Visitor>
    bool traverse(std::uint32_t grid, const Ray& ray, const Vector3& inverse_direction,
                  Visitor& visitor) const;
    /// The unbounded primitives, then the grids along the ray (detail::grid_query's walk).
    template <class Visitor>
    bool walk(const Ray& ray, Visitor& visitor) const;
    using AcceleratorBase<HierarchicalGrid<Set>, Set>::stats_;

    const Set* set_ = nullptr;
    HierarchicalGridConfig config_;
    double scene_scale_ = 0.0;
    int depth_ = 0;
    std::vector<Grid> grids_;
    std::vector<Cell> cells_;
    std::vector<std::uint32_t> primitives_;
    std::vector<std::uint32_t> unbounded_;
};

extern template class HierarchicalGrid<TriangleSet<float>>;
extern template class HierarchicalGrid<TriangleSet<double>>;
extern template class HierarchicalGrid<ShapeSet>;

}  // namespace csgrt
