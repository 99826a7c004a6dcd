#include "csgrt/accel/hierarchical_grid.h"

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

namespace {

/// Costs of the subdivision estimate, in units of one primitive test: entering a sub-grid
/// (box clip and DDA setup) and stepping through one cell. Measured roughly on the float
/// triangle test; the decision is not sensitive to them within a factor of two.
constexpr double kSubGridCost = 2.0;
constexpr double kCellCost = 0.3;
constexpr std::size_t kMaxReferenceGrowth = 8;

/// Whether a cell listing `count` primitives should hold the sub-grid `geometry` (with lists
/// `offsets`) instead. Three conditions:
/// - it separates them: no sub-cell lists all of them;
/// - it does not multiply long lists: more than kMaxReferenceGrowth references per primitive
///   are accepted only while every sub-cell's list fits the mailbox. Primitives no sub-grid
///   can separate (identical or nearly so, or all crossing one spot) would be listed again in
///   every sub-cell and, beyond the mailbox's slots, tested again in each; long thin
///   primitives legitimately cross many sub-cells, in short lists;
/// - it is cheaper for a random ray through the cell: the sub-grid's box clip, plus each
///   sub-cell's step and list weighted by the chance a ray through the cell crosses that
///   sub-cell (the ratio of surface areas, as in the SAH: Goldsmith & Salmon 1987, MacDonald
///   & Booth 1990), against testing the whole list.
bool sub_grid_pays(const detail::GridGeometry& geometry, const std::vector<std::uint32_t>& offsets,
                   std::size_t count, double cell_area) {
    const Vector3 size = geometry.cell_size;
    const double sub_cell_area =
        2.0 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
    const double crossing = sub_cell_area / cell_area;
    double cost = kSubGridCost;
    std::uint32_t longest = 0;
    for (std::size_t c = 0; c < geometry.cell_count(); ++c) {
        const std::uint32_t listed = offsets[c + 1] - offsets[c];
        longest = std::max(longest, listed);
        cost += crossing * (kCellCost + double(listed));
    }
    if (longest == count) return false;
    if (offsets.back() > kMaxReferenceGrowth * count && longest > detail::Mailbox::kSlots)
        return false;
    return cost < double(count);
}

}  // namespace

template <class Set>
void HierarchicalGrid<Set>::build(const Set& set, const HierarchicalGridConfig& config) {
    const std::string_view what = "HierarchicalGrid";
    require(config.top_cells_exponent >= 0.0 && config.top_cells_exponent <= 1.0, what,
            "top_cells_exponent", "in [0, 1]", config.top_cells_exponent);
    require(config.max_primitives_per_cell >= 1, what, "max_primitives_per_cell", ">= 1",
            config.max_primitives_per_cell);
    require(config.sub_cells_per_primitive > 0.0 && std::isfinite(config.sub_cells_per_primitive),
            what, "sub_cells_per_primitive", "> 0 and finite", config.sub_cells_per_primitive);
    require(config.max_depth >= 0 && config.max_depth <= 8, what, "max_depth", "in [0, 8]",
            config.max_depth);
    require(config.max_resolution >= 1 && config.max_resolution <= 4096, what, "max_resolution",
            "in [1, 4096]", config.max_resolution);
    const auto start = std::chrono::steady_clock::now();
    set_ = &set;
    config_ = config;
    depth_ = 0;
    grids_.clear();
    cells_.clear();
    primitives_.clear();
    unbounded_.clear();
    std::vector<std::uint32_t> bounded;
    const Aabb bounds = detail::grid_bounds(set, bounded, unbounded_, scene_scale_);
    if (!bounded.empty()) {
        // The top grid is a regular grid of about N^exponent cells; its lists are refined in
        // place rather than rebuilt.
        const double count = double(bounded.size());
        const double density = std::pow(count, config.top_cells_exponent) / count;
        const detail::GridGeometry top =
            detail::choose_grid_geometry(bounds, bounded.size(), density, config.max_resolution);
        std::vector<std::uint32_t> offsets, lists;
        detail::fill_cells(set, bounded, top, scene_scale_, config.triangle_box_test, offsets,
                           lists);
        add_grid(set, top, offsets, lists, 0);
    }
    grids_.shrink_to_fit();
    cells_.shrink_to_fit();
    primitives_.shrink_to_fit();
    unbounded_.shrink_to_fit();

    stats_ = AcceleratorStats{};
    stats_.name = "hgrid";
    stats_.primitives = set.size();
    stats_.nodes = cells_.size();
    stats_.references = primitives_.size() + unbounded_.size();
    stats_.bytes = grids_.capacity() * sizeof(Grid) + cells_.capacity() * sizeof(Cell) +
                   (primitives_.capacity() + unbounded_.capacity()) * sizeof(std::uint32_t);
    std::ostringstream details;
    details.precision(3);
    const auto& top = grids_.empty() ? detail::GridGeometry{} : grids_[0].geometry;
    details << "top " << top.resolution[0] << "x" << top.resolution[1] << "x" << top.resolution[2]
            << ", " << grids_.size() << " grids, depth " << depth_ << ", "
            << (bounded.empty() ? 0.0 : double(primitives_.size()) / double(bounded.size()))
            << " references per primitive, " << unbounded_.size() << " unbounded";
    stats_.details = details.str();
    stats_.build_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class Set>
std::uint32_t HierarchicalGrid<Set>::add_grid(const Set& set, const detail::GridGeometry& geometry,
                                              const std::vector<std::uint32_t>& offsets,
                                              const std::vector<std::uint32_t>& lists, int depth) {
    const auto index = static_cast<std::uint32_t>(grids_.size());
    const auto first = static_cast<std::uint32_t>(cells_.size());
    grids_.push_back(Grid{geometry, first});
    cells_.resize(cells_.size() + geometry.cell_count());
    depth_ = std::max(depth_, depth);
    std::vector<std::uint32_t> sub_offsets, sub_lists;
    for (int z = 0; z < geometry.resolution[2]; ++z) {
        for (int y = 0; y < geometry.resolution[1]; ++y) {
            for (int x = 0; x < geometry.resolution[0]; ++x) {
                const std::size_t c = geometry.cell_index(x, y, z);
                const std::span<const std::uint32_t> members(lists.data() + offsets[c],
                                                             offsets[c + 1] - offsets[c]);
                if (members.size() > std::size_t(config_.max_primitives_per_cell) &&
                    depth < config_.max_depth) {
                    // The sub-grid covers the cell (grown by a rounding margin, so rays the
                    // DDA assigns to this cell near a face still enter it) shrunk to the
                    // members' padded boxes.
                    const Aabb cell = geometry.cell_box(x, y, z);
                    Aabb members_box;
                    for (const std::uint32_t m : members) {
                        const Aabb box = set.bounds(m);
                        members_box.extend(
                            detail::padded(box, detail::primitive_padding(box, scene_scale_)));
                    }
                    const Aabb sub_bounds =
                        overlap(detail::padded(cell, detail::kPrimitivePadding *
                                                         detail::coordinate_scale(cell)),
                                members_box);
                    const double cell_area = cell.surface_area();
                    if (!sub_bounds.is_empty() && cell_area > 0.0) {
                        const detail::GridGeometry sub = detail::choose_grid_geometry(
                            sub_bounds, members.size(), config_.sub_cells_per_primitive,
                            config_.max_resolution);
                        detail::fill_cells(set, members, sub, scene_scale_,
                                           config_.triangle_box_test, sub_offsets, sub_lists);
                        if (sub_grid_pays(sub, sub_offsets, members.size(), cell_area)) {
                            const std::uint32_t child =
                                add_grid(set, sub, sub_offsets, sub_lists, depth + 1);
                            cells_[first + c] = Cell{child, kSubGrid};
                            continue;
                        }
                    }
                }
                cells_[first + c] = Cell{static_cast<std::uint32_t>(primitives_.size()),
                                         static_cast<std::uint32_t>(members.size())};
                primitives_.insert(primitives_.end(), members.begin(), members.end());
            }
        }
    }
    return index;
}

template <class Set>
std::span<const std::uint32_t> HierarchicalGrid<Set>::primitives_at(const Point3& p) const {
    std::uint32_t grid_index = 0;
    while (grid_index < grids_.size()) {
        const Grid& grid = grids_[grid_index];
        if (!grid.geometry.bounds.contains(p)) return {};
        const Cell& cell = cells_[grid.first_cell + grid.geometry.cell_index(
                                                        grid.geometry.cell_coordinate(p.x(), 0),
                                                        grid.geometry.cell_coordinate(p.y(), 1),
                                                        grid.geometry.cell_coordinate(p.z(), 2))];
        if (cell.count != kSubGrid)
            return std::span<const std::uint32_t>(primitives_.data() + cell.begin, cell.count);
        grid_index = cell.begin;
    }
    return {};
}

template <class Set>
template <class Visitor>
bool HierarchicalGrid<Set>::traverse(std::uint32_t grid_index, const Ray& ray,
                                     const Vector3& inverse_direction, Visitor& visitor) const {
    const Grid& grid = grids_[grid_index];
    double t_enter, t_exit;
    visitor.count_box();
    if (!detail::clip_to_box(grid.geometry.bounds, ray, inverse_direction, t_enter, t_exit))
        return false;
    bool stop = false;
    detail::walk_cells(grid.geometry, ray, inverse_direction, t_enter, t_exit,
                       [&](std::size_t cell_index, double cell_exit) {
                           visitor.count_cell();
                           const Cell& cell = cells_[grid.first_cell + cell_index];
                           if (cell.count == kSubGrid) {
                               stop = traverse(cell.begin, ray, inverse_direction, visitor);
                           } else {
                               stop = visitor.leaf(std::span<const std::uint32_t>(
                                   primitives_.data() + cell.begin, cell.count));
                           }
                           // Every later cell, at this level or above, begins after this one
                           // ends, so a hit before its exit ends the whole walk.
                           return stop = stop || visitor.done(cell_exit);
                       });
    return stop;
}

template <class Set>
template <class Visitor>
bool HierarchicalGrid<Set>::walk(const Ray& ray, Visitor& visitor) const {
    if (visitor.leaf(unbounded_)) return true;
    return !grids_.empty() && traverse(0, ray, ray.direction.cwiseInverse(), visitor);
}

template <class Set>
template <QueryKind kKind, bool kCounted>
bool HierarchicalGrid<Set>::query(const Ray& ray, QueryAnswer<kKind>& answer, QueryScratch& scratch,
                                  TraversalCounters& counters) const {
    return detail::grid_query<kKind, kCounted>(set_, scene_scale_, ray, answer, scratch, counters,
                                               [&](auto& visitor) { return walk(ray, visitor); });
}

template class HierarchicalGrid<TriangleSet<float>>;
template class HierarchicalGrid<TriangleSet<double>>;
template class HierarchicalGrid<ShapeSet>;

}  // namespace csgrt

CSGRT_INSTANTIATE_ACCELERATOR_BASE(csgrt::HierarchicalGrid);
