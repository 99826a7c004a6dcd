#pragma once

// Build and traversal machinery shared by the regular and the hierarchical grid: padding,
// cell assignment, the cell walk, and the three queries as visitors of that walk (private to
// accel/src).

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/regular_grid.h"
#include "csgrt/accel/shape_set.h"

namespace csgrt::detail {

/// Primitive boxes are grown before they are assigned to cells, because the float triangle
/// test reports hits up to a rounding error outside the exact triangle (Woop et al. 2013: the
/// corners are rounded relative to the origin, about 2^-24 (|corner| + |origin| + distance)),
/// and the DDA decides boundaries in double. A hit brute force reports must lie in a cell the
/// ray visits. The growth is relative to the primitive's own coordinates plus a smaller share
/// of the scene's, so a small dense object in a huge scene keeps a tight fit.
inline constexpr double kPrimitivePadding = 1e-5;
inline constexpr double kScenePadding = 1e-6;

/// A ray stops at the end of a cell only if the best hit lies before the cell's exit by this
/// relative margin (of |t| and of the ray's coordinate scale over |d|): a primitive in a later
/// cell may report a t slightly smaller than where it truly crosses the ray (float rounding
/// again), and stopping exactly at the exit would miss it when it ties or wins.
inline constexpr double kStopMargin = 1e-5;

/// The largest |coordinate| of `box` plus its largest extent: the magnitude rounding errors
/// of points in or near it are relative to.
inline double coordinate_scale(const Aabb& box) {
    return std::max(box.lower.cwiseAbs().maxCoeff(), box.upper.cwiseAbs().maxCoeff()) +
           box.diagonal().maxCoeff();
}

/// Whether a primitive with box `box` can be put in cells: finite and non-empty.
inline bool is_cell_assignable(const Aabb& box) {
    return box.is_finite() && !box.is_empty();
}

/// How far `box` (of one primitive) is grown in every direction.
inline double primitive_padding(const Aabb& box, double scene_scale) {
    return kPrimitivePadding * coordinate_scale(box) + kScenePadding * scene_scale;
}

inline Aabb padded(const Aabb& box, double padding) {
    return Aabb(box.lower - Vector3::Constant(padding), box.upper + Vector3::Constant(padding));
}

/// The separating-axis test of one triangle against boxes of one size (a grid's cells, grown
/// by the padding): Akenine-Moeller, "Fast 3D Triangle-Box Overlap Testing", JGT 6(1), 2001.
/// The candidate axes are the triangle's normal and the nine cross products of its edges
/// with the box axes (the box axes themselves are settled by the range of cells the caller
/// visits). The triangle's extent and the box's radius along each axis are computed once per
/// triangle, so each cell costs one dot product per axis. Degenerate triangles give zero
/// axes, which separate nothing: they stay wherever their box is.
class TriangleBoxTest {
public:
    TriangleBoxTest(const std::array<Vector3, 3>& corners, const Vector3& half) {
        const std::array<Vector3, 3> edges = {corners[1] - corners[0], corners[2] - corners[1],
                                              corners[0] - corners[2]};
        add(edges[0].cross(edges[1]), corners, half);
        for (const Vector3& edge : edges) {
            for (int axis = 0; axis < 3; ++axis) {
                // The axis e_axis x edge, written out: its component along `axis` is zero.
                Vector3 direction = Vector3::Zero();
                const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
                direction[a1] = -edge[a2];
                direction[a2] = edge[a1];
                add(direction, corners, half);
            }
        }
    }

    /// Whether the triangle overlaps the box of half-size `half` centred at `center`.
    bool overlaps(const Point3& center) const {
        for (int k = 0; k < count_; ++k) {
            const double c = axes_[k].dot(center);
            if (lo_[k] - c > radius_[k] || c - hi_[k] > radius_[k]) return false;
        }
        return true;
    }

private:
    void add(const Vector3& axis, const std::array<Vector3, 3>& corners, const Vector3& half) {
        if (axis == Vector3::Zero()) return;
        const double p0 = axis.dot(corners[0]), p1 = axis.dot(corners[1]),
                     p2 = axis.dot(corners[2]);
        axes_[count_] = axis;
        lo_[count_] = std::min({p0, p1, p2});
        hi_[count_] = std::max({p0, p1, p2});
        radius_[count_] = half.dot(axis.cwiseAbs());
        ++count_;
    }

    std::array<Vector3, 10> axes_;
    std::array<double, 10> lo_, hi_, radius_;
    int count_ = 0;
};

template <class Set>
concept HasTriangleCorners = requires(const Set& set, std::size_t i) {
    set.corner(i, 0);
};

/// Calls visit(cell index) for every cell of `grid` that primitive `primitive` (box grown by
/// its padding) overlaps: every cell of its box, or, for triangles with `triangle_test`, only
/// the cells the grown triangle overlaps.
template <class Set, class Visit>
void for_each_overlapped_cell(const Set& set, std::uint32_t primitive, const GridGeometry& grid,
                              double scene_scale, bool triangle_test, Visit&& visit) {
    const Aabb box = set.bounds(primitive);
    const double padding = primitive_padding(box, scene_scale);
    const Aabb grown = padded(box, padding);
    std::array<int, 3> lo, hi;
    for (int axis = 0; axis < 3; ++axis) {
        lo[axis] = grid.cell_coordinate(grown.lower[axis], axis);
        hi[axis] = grid.cell_coordinate(grown.upper[axis], axis);
    }
    const bool single_cell = lo == hi;
    if constexpr (HasTriangleCorners<Set>) {
        if (triangle_test && !single_cell) {
            std::array<Vector3, 3> corners;
            for (int k = 0; k < 3; ++k)
                corners[k] = set.corner(primitive, k).template cast<double>();
            const TriangleBoxTest test(corners, 0.5 * grid.cell_size + Vector3::Constant(padding));
            for (int z = lo[2]; z <= hi[2]; ++z) {
                for (int y = lo[1]; y <= hi[1]; ++y) {
                    for (int x = lo[0]; x <= hi[0]; ++x) {
                        const Point3 center =
                            grid.bounds.lower + (Vector3(x, y, z) + Vector3::Constant(0.5))
                                                    .cwiseProduct(grid.cell_size);
                        if (test.overlaps(center)) visit(grid.cell_index(x, y, z));
                    }
                }
            }
            return;
        }
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
        for (int y = lo[1]; y <= hi[1]; ++y) {
            for (int x = lo[0]; x <= hi[0]; ++x) visit(grid.cell_index(x, y, z));
        }
    }
}

/// Asks the memory system for the triangles of a cell's list before they are tested, so that
/// their cache misses overlap instead of queueing one per test (incoherent rays miss on most
/// of them). Only triangle sets expose where a primitive's data lives.
template <class Set>
inline void prefetch_primitives(const Set& set, const std::uint32_t* begin,
                                const std::uint32_t* end) {
    if constexpr (HasTriangleCorners<Set>) {
        for (const std::uint32_t* p = begin; p != end; ++p) __builtin_prefetch(&set.corner(*p, 0));
    }
}

/// Fills the CSR cell lists of `grid` with `members` (primitive indices, ascending): a count
/// pass, a prefix sum, and a fill pass, so the lists are allocated once at their exact size.
/// Cell c lists primitives[offsets[c] .. offsets[c + 1]).
template <class Set>
void fill_cells(const Set& set, std::span<const std::uint32_t> members, const GridGeometry& grid,
                double scene_scale, bool triangle_test, std::vector<std::uint32_t>& offsets,
                std::vector<std::uint32_t>& primitives) {
    offsets.assign(grid.cell_count() + 1, 0);
    for (const std::uint32_t primitive : members) {
        for_each_overlapped_cell(set, primitive, grid, scene_scale, triangle_test,
                                 [&](std::size_t cell) { ++offsets[cell + 1]; });
    }
    for (std::size_t cell = 0; cell < grid.cell_count(); ++cell) offsets[cell + 1] += offsets[cell];
    primitives.assign(offsets.back(), 0);
    std::vector<std::uint32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (const std::uint32_t primitive : members) {
        for_each_overlapped_cell(set, primitive, grid, scene_scale, triangle_test,
                                 [&](std::size_t cell) { primitives[cursor[cell]++] = primitive; });
    }
}

/// The primitives' padded boxes joined (finite, non-empty ones only) and the scene scale the
/// padding is relative to; the others go to `unbounded`.
template <class Set>
Aabb grid_bounds(const Set& set, std::vector<std::uint32_t>& bounded,
                 std::vector<std::uint32_t>& unbounded, double& scene_scale) {
    Aabb exact;
    for (std::size_t i = 0; i < set.size(); ++i) {
        const Aabb box = set.bounds(i);
        if (is_cell_assignable(box)) {
            exact.extend(box);
            bounded.push_back(static_cast<std::uint32_t>(i));
        } else {
            unbounded.push_back(static_cast<std::uint32_t>(i));
        }
    }
    scene_scale = bounded.empty() ? 0.0 : coordinate_scale(exact);
    Aabb grown;
    for (const std::uint32_t i : bounded) {
        const Aabb box = set.bounds(i);
        grown.extend(padded(box, primitive_padding(box, scene_scale)));
    }
    return grown;
}

/// A per-ray mailbox (Amanatides & Woo 1987) made thread-safe by living on the ray's stack and
/// hashing primitive indices into a few slots (https://pixelesque.net/blog/2012/05/hashed-
/// mailboxing): a primitive seen in an earlier cell is skipped unless another primitive has
/// since taken its slot, in which case it is merely tested again.
class Mailbox {
public:
    Mailbox() { std::memset(slots_.data(), 0xff, sizeof(slots_)); }

    /// True when `primitive` is not in its slot (then it is put there): test it.
    bool first_visit(std::uint32_t primitive) {
        std::uint32_t& slot = slots_[primitive & (kSlots - 1)];
        if (slot == primitive) return false;
        slot = primitive;
        return true;
    }

    static constexpr std::uint32_t kSlots = 64;

private:
    std::array<std::uint32_t, kSlots> slots_;
};

/// When a nearest-hit search may stop: after a cell whose exit lies beyond the best hit by the
/// margin explained at kStopMargin.
class StopRule {
public:
    StopRule(const Ray& ray, double scene_scale)
        : absolute_(kStopMargin * (ray.origin.cwiseAbs().maxCoeff() + scene_scale) /
                    ray.direction.cwiseAbs().maxCoeff()) {}

    bool done(double best_t, double cell_exit) const {
        return best_t + kStopMargin * std::abs(best_t) + absolute_ < cell_exit;
    }

private:
    double absolute_;
};

/// The part [t_enter, t_exit] of [ray.t_min, ray.t_max] inside `box`, or false: the same
/// conservative slab test as Aabb::intersect (Ize, "Robust BVH Ray Traversal", JCGT 2013:
/// t_far grown by 2 gamma(3) |t_far|, NaN slabs ignored), written out per axis so it inlines
/// into the traversal, which calls it once per grid entered.
inline bool clip_to_box(const Aabb& box, const Ray& ray, const Vector3& inverse_direction,
                        double& t_enter, double& t_exit) {
    double t0 = ray.t_min, t1 = ray.t_max;
    for (int axis = 0; axis < 3; ++axis) {
        const double a = (box.lower[axis] - ray.origin[axis]) * inverse_direction[axis];
        const double b = (box.upper[axis] - ray.origin[axis]) * inverse_direction[axis];
        const double t_near = a < b ? a : b;
        double t_far = a < b ? b : a;
        t_far *= t_far >= 0.0 ? 1.0 + 2.0 * gamma(3) : 1.0 - 2.0 * gamma(3);
        t0 = t_near > t0 ? t_near : t0;
        t1 = t_far < t1 ? t_far : t1;
    }
    t_enter = t0;
    t_exit = t1;
    return t0 <= t1;
}

/// Jumps over fewer empty cells than this cost more than stepping through them.
inline constexpr int kMinimumJump = 3;

/// Walks the cells of `grid` that the ray crosses between t_enter and t_exit (a part of the
/// ray inside grid.bounds), in order, with the 3D-DDA of Amanatides & Woo 1987. Calls
/// visit(cell index, cell exit t) for each and stops when it returns true.
///
/// The start cell is the clamped cell of the entry point, so a rounded entry point never
/// leaves the grid; if rounding put it one cell early, that cell's exit lies before t_enter
/// and the walk simply moves on. Each step adds a cell's width in t to the crossed axis's
/// next boundary (Amanatides & Woo's tDelta): after k steps the error is k ulps, far below
/// the padding of the cells. Every step advances a cell coordinate toward the grid's end, so
/// the walk ends after at most nx + ny + nz steps whatever the t values do (even if they stop
/// increasing for a ray from absurdly far away). An axis whose direction reciprocal is
/// infinite (zero or denormal component) never steps: the ray moves less than a rounding
/// error along it inside the grid.
///
/// `empty_radius(cell index)` may report that every cell within Chebyshev distance r - 1 of
/// the cell is empty (r = 0 or 1: nothing known). For r >= kMinimumJump the walk then leaves
/// that cube of empty cells in one jump, as proximity clouds do (Cohen & Sheffer, "Proximity
/// Clouds", The Visual Computer 1994): the axis whose boundary r - 1 cells on is nearest
/// crosses r planes, the others the planes they cross before it, so the walk lands in the
/// cell the DDA would have reached. Counting those planes rounds only where the ray passes
/// within a rounding error of a cell edge, where the cell padding covers either choice.
template <class Visit, class EmptyRadius>
inline void walk_cells(const GridGeometry& grid, const Ray& ray, const Vector3& inverse_direction,
                       double t_enter, double t_exit, Visit&& visit, EmptyRadius&& empty_radius) {
    const Point3 entry = ray.at(t_enter);
    int cell[3], step[3], end[3];
    double t_next[3], t_delta[3];
    for (int axis = 0; axis < 3; ++axis) {
        cell[axis] = grid.cell_coordinate(entry[axis], axis);
        const double inverse = inverse_direction[axis];
        if (!std::isfinite(inverse)) {
            step[axis] = 0;
            end[axis] = -1;
            t_next[axis] = kInfinity;
            t_delta[axis] = 0.0;
            continue;
        }
        step[axis] = inverse > 0.0 ? 1 : -1;
        end[axis] = inverse > 0.0 ? grid.resolution[axis] : -1;
        const int boundary = cell[axis] + (inverse > 0.0 ? 1 : 0);
        const double plane = grid.bounds.lower[axis] + boundary * grid.cell_size[axis];
        t_next[axis] = (plane - ray.origin[axis]) * inverse;
        t_delta[axis] = grid.cell_size[axis] * std::abs(inverse);
    }
    // Scalars rather than arrays indexed by the crossed axis keep the loop in registers.
    double tx = t_next[0], ty = t_next[1], tz = t_next[2];
    int x = cell[0], y = cell[1], z = cell[2];
    const std::ptrdiff_t step_y = std::ptrdiff_t(step[1]) * grid.resolution[0];
    const std::ptrdiff_t step_z =
        std::ptrdiff_t(step[2]) * grid.resolution[0] * std::ptrdiff_t(grid.resolution[1]);
    std::ptrdiff_t index = std::ptrdiff_t(grid.cell_index(x, y, z));
    for (;;) {
        const double t_cross = std::min(tx, std::min(ty, tz));
        if (visit(std::size_t(index), t_cross < t_exit ? t_cross : t_exit)) return;
        if (!(t_cross < t_exit)) return;
        const int radius = empty_radius(std::size_t(index));
        if (radius >= kMinimumJump) {
            const int reach = radius - 1;
            const double lx = tx + reach * t_delta[0], ly = ty + reach * t_delta[1],
                         lz = tz + reach * t_delta[2];
            const double t_leave = std::min(lx, std::min(ly, lz));
            if (!(t_leave < t_exit)) return;
            // Planes of one axis crossed before t_leave (at most reach), or reach + 1 for the
            // axis that leaves the cube.
            auto crossed = [&](double t, double l, double delta) {
                if (l == t_leave) return reach + 1;
                if (!(t < t_leave)) return 0;
                const double planes = std::ceil((t_leave - t) / delta);
                return planes < reach ? int(planes) : reach;
            };
            const int mx = crossed(tx, lx, t_delta[0]), my = crossed(ty, ly, t_delta[1]),
                      mz = crossed(tz, lz, t_delta[2]);
            x += step[0] * mx;
            y += step[1] * my;
            z += step[2] * mz;
            if (x < 0 || x >= grid.resolution[0] || y < 0 || y >= grid.resolution[1] || z < 0 ||
                z >= grid.resolution[2])
                return;
            tx += mx * t_delta[0];
            ty += my * t_delta[1];
            tz += mz * t_delta[2];
            index = std::ptrdiff_t(grid.cell_index(x, y, z));
            continue;
        }
        if (t_cross == tx) {
            x += step[0];
            if (x == end[0]) return;
            index += step[0];
            tx += t_delta[0];
        } else if (t_cross == ty) {
            y += step[1];
            if (y == end[1]) return;
            index += step_y;
            ty += t_delta[1];
        } else {
            z += step[2];
            if (z == end[2]) return;
            index += step_z;
            tz += t_delta[2];
        }
    }
}

/// walk_cells without jumps.
template <class Visit>
inline void walk_cells(const GridGeometry& grid, const Ray& ray, const Vector3& inverse_direction,
                       double t_enter, double t_exit, Visit&& visit) {
    walk_cells(grid, ray, inverse_direction, t_enter, t_exit, visit, [](std::size_t) { return 0; });
}

/// Removes from hits[first ..] the records of members recorded more than once. The hashed
/// mailbox forgets a primitive whose slot another one took, so all_hits may test (and record)
/// it again; its records are identical, and sorting by member drops the copies exactly.
template <class Set>
void drop_repeated_hits(std::vector<HitRecord>& hits, std::size_t first) {
    const auto begin = hits.begin() + std::ptrdiff_t(first);
    std::sort(begin, hits.end(), [](const HitRecord& a, const HitRecord& b) {
        return member_of<Set>(a) < member_of<Set>(b);
    });
    hits.erase(std::unique(begin, hits.end(),
                           [](const HitRecord& a, const HitRecord& b) {
                               return member_of<Set>(a) == member_of<Set>(b);
                           }),
               hits.end());
}

/// What a grid's walk does with the primitives it reaches, for one query kind (Derived:
/// NearestCells, AnyCells, AllCells). `leaf(list)` tests a cell's primitives not seen in an
/// earlier cell (the mailbox), `test(primitive)` tests one, and both return true to end the
/// walk; `done(cell_exit)` says whether the walk may end after a cell that ends there;
/// count_box and count_cell count the walk's boxes and cells when kCount.
template <class Derived, class Set, bool kCount>
class CellVisitor {
public:
    CellVisitor(const Set& set, const typename Set::PreparedRay& prepared,
                TraversalCounters& counters)
        : set_(set), prepared_(prepared), counters_(counters) {}

    void count_box() {
        if constexpr (kCount) ++counters_.boxes_tested;
    }
    void count_cell() {
        if constexpr (kCount) ++counters_.nodes_visited;
    }
    bool test(std::uint32_t primitive) {
        if constexpr (kCount) ++counters_.primitives_tested;
        return static_cast<Derived&>(*this).test_uncounted(primitive);
    }
    bool leaf(std::span<const std::uint32_t> list) {
        prefetch_primitives(set_, list.data(), list.data() + list.size());
        for (const std::uint32_t primitive : list) {
            if (mailbox_.first_visit(primitive) && test(primitive)) return true;
        }
        return false;
    }

protected:
    const Set& set_;
    const typename Set::PreparedRay& prepared_;

private:
    TraversalCounters& counters_;
    Mailbox mailbox_;
};

/// Nearest hit: a hit beyond the current cell's exit is kept, not accepted (a primitive in a
/// later cell may be nearer), and the walk ends after the first cell (at any level) that
/// ends beyond the best hit by the stop rule's margin.
template <class Set, bool kCount>
class NearestCells : public CellVisitor<NearestCells<Set, kCount>, Set, kCount> {
public:
    NearestCells(const Set& set, const typename Set::PreparedRay& prepared, const Ray& ray,
                 double scene_scale, TraversalCounters& counters)
        : CellVisitor<NearestCells, Set, kCount>(set, prepared, counters), stop_(ray, scene_scale) {
        best.t = ray.t_max;
    }
    bool test_uncounted(std::uint32_t primitive) {
        found |= this->set_.intersect(primitive, this->prepared_, best);
        return false;
    }
    bool done(double cell_exit) const { return found && stop_.done(best.t, cell_exit); }

    HitRecord best;
    bool found = false;

private:
    StopRule stop_;
};

/// Occlusion: the first hit anywhere in the interval ends the walk.
template <class Set, bool kCount>
class AnyCells : public CellVisitor<AnyCells<Set, kCount>, Set, kCount> {
public:
    using CellVisitor<AnyCells, Set, kCount>::CellVisitor;
    bool test_uncounted(std::uint32_t primitive) {
        return this->set_.occluded(primitive, this->prepared_);
    }
    bool done(double) const { return false; }
};

/// Every hit in the interval: the whole ray is walked, each hit appended to `hits`.
template <class Set, bool kCount>
class AllCells : public CellVisitor<AllCells<Set, kCount>, Set, kCount> {
public:
    AllCells(const Set& set, const typename Set::PreparedRay& prepared, double t_max,
             std::vector<HitRecord>& hits, TraversalCounters& counters)
        : CellVisitor<AllCells, Set, kCount>(set, prepared, counters), t_max_(t_max), hits_(hits) {}
    bool test_uncounted(std::uint32_t primitive) {
        HitRecord record;
        record.t = t_max_;
        if (this->set_.intersect(primitive, this->prepared_, record)) hits_.push_back(record);
        return false;
    }
    bool done(double) const { return false; }

private:
    double t_max_;
    std::vector<HitRecord>& hits_;
};

/// A grid's answer to a query of kind kKind over `set` (null before the grid is built): the
/// visitor of that kind handed to `walk(visitor)`, the grid's own walk of its unbounded
/// primitives and cells, which returns true when the visitor ended it. Returns whether the
/// query found something, as AcceleratorBase expects; a nearest record is written only then.
template <QueryKind kKind, bool kCount, class Set, class Walk>
bool grid_query(const Set* set, double scene_scale, const Ray& ray, QueryAnswer<kKind>& answer,
                QueryScratch& scratch, TraversalCounters& counters, Walk&& walk) {
    if (set == nullptr || !is_valid(ray)) return false;
    const auto prepared = set->prepare(ray, scratch);
    if constexpr (kKind == QueryKind::kNearest) {
        NearestCells<Set, kCount> visitor(*set, prepared, ray, scene_scale, counters);
        walk(visitor);
        if (visitor.found) answer = visitor.best;
        return visitor.found;
    } else if constexpr (kKind == QueryKind::kAny) {
        AnyCells<Set, kCount> visitor(*set, prepared, counters);
        return walk(visitor);
    } else {
        const std::size_t first = answer.size();
        AllCells<Set, kCount> visitor(*set, prepared, ray.t_max, answer, counters);
        walk(visitor);
        drop_repeated_hits<Set>(answer, first);
        return answer.size() > first;
    }
}

}  // namespace csgrt::detail
