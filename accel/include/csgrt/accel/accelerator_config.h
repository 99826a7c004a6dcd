#pragma once

#include <cstddef>
#include <cstdint>

namespace csgrt {

// The configuration of every structure, in one header: what a user of the factory (a scene, a
// compound, a mesh) needs to choose a structure and tune it, without including the structures.

/// How BruteForce tests its primitives.
struct BruteForceConfig {
    /// Test each primitive's bounding box before the primitive: measures what bounding boxes
    /// alone buy (the seed's first speed-up) against the plain loop.
    bool box_culling = false;
};

/// How a RegularGrid sizes its cells.
struct GridConfig {
    /// Target number of cells per primitive (the grid density): the cell edge is
    /// a = cbrt(V / (cells_per_primitive N)) for N primitives in a box of volume V, so the grid
    /// has about cells_per_primitive N cells. The literature writes a = cbrt(lambda V / N), with
    /// lambda = 1 / cells_per_primitive; Ize et al. 2007 show Theta(N) cells is right for
    /// well-shaped meshes. Must be > 0.
    double cells_per_primitive = 8.0;
    /// Most cells along one axis (the clamp of the per-axis counts), >= 1. Keeps memory bounded
    /// for very elongated or very large scenes.
    int max_resolution = 256;
    /// For triangle sets: reference a triangle only from the cells the triangle itself
    /// overlaps (Akenine-Moeller, "Fast 3D Triangle-Box Overlap Testing", JGT 2001), not from
    /// every cell of its bounding box. Long, thin, diagonal triangles touch far fewer cells.
    bool triangle_box_test = true;
};

/// How a HierarchicalGrid sizes its top grid and decides which cells get sub-grids.
struct HierarchicalGridConfig {
    /// The top grid has about N^top_cells_exponent cells for N primitives. Ize, Shirley and
    /// Parker, "Grid Creation Strategies for Efficient Ray Tracing", 2007, derive N^0.6 for
    /// one level of nesting (N^(3 / (3 + 2 d)) for d levels). In [0, 1].
    double top_cells_exponent = 0.6;
    /// Cells listing more than this many primitives are considered for a sub-grid (>= 1).
    int max_primitives_per_cell = 16;
    /// Density of each sub-grid, in cells per primitive of the cell it refines (> 0).
    double sub_cells_per_primitive = 2.0;
    /// Most levels of sub-grids below the top grid, in [0, 8] (0: a plain grid).
    int max_depth = 3;
    /// Most cells along one axis of any one grid (>= 1).
    int max_resolution = 128;
    /// As GridConfig::triangle_box_test, at every level.
    bool triangle_box_test = true;
};

/// How a ray-space cell picks the axis it is halved along.
enum class RayClassificationSplit {
    /// x, y, z, u, v in turn, by depth (Arvo & Kirk's order).
    kCycle,
    /// The axis whose halving narrows the cell's beam the most: the beam's width across the
    /// rays is estimated from the origin extents, the origin extent along the face axis seen
    /// at the rays' slope, and the direction extents times how far the rays can still travel
    /// through the scene (docs/structures.md).
    kNarrowBeam,
};

/// How a RayClassification splits ray space and how much memory its lists may take.
struct RayClassificationConfig {
    /// A leaf that a ray reaches is split while its candidates hold more primitives than this.
    std::uint32_t max_leaf_candidates = 16;
    /// The deepest a face's tree may grow (halvings from its root), at most 60; 0 chooses
    /// round(2.4 log2 n) for n primitives (38 for 50k), about where a cell's beam narrows to
    /// the size of one primitive of an evenly tessellated surface.
    int max_depth = 0;
    /// Cap on the bytes of all candidate lists and cells, the six roots included. Once it is
    /// reached cells stop splitting, and a new cell whose list would not fit searches its
    /// parent's list; stats() reports how often either happened. Answers stay exact whatever
    /// the cap (0: the six root cells only).
    std::size_t max_candidate_bytes = std::size_t{256} << 20;
    RayClassificationSplit split = RayClassificationSplit::kNarrowBeam;
    /// A leaf is split only once this many queries have searched it, so a cell that few
    /// incoherent rays reach is searched, not refined for nobody (>= 1; 1: at the first).
    std::uint32_t visits_before_split = 64;
    /// A candidate cluster is replaced by its two halves while it is wider across the rays
    /// than this many times the cell's beam (> 0): smaller values give longer, tighter lists.
    double cluster_width = 2.0;
    /// Subdivide every cell with more than max_leaf_candidates primitives down to this depth
    /// during build(), before any ray arrives (0: purely lazy).
    int build_depth = 0;
};

/// How a Bvh is built and laid out. The SAH costs are relative: only their ratio matters.
struct BvhConfig {
    /// Bins per axis of the binned SAH (Wald 2007); 16 to 32 is the usual trade-off between
    /// build time and tree quality. Must be in [2, 256].
    int bins = 16;
    /// A node with more primitives than this is always split (if its centroids differ); a
    /// smaller one becomes a leaf when the SAH says splitting does not pay. Must be >= 1.
    int max_leaf_size = 8;
    /// SAH cost of visiting a node (testing its children's boxes). Must be > 0.
    double traversal_cost = 1.0;
    /// SAH cost of one primitive test. Must be > 0.
    double intersection_cost = 1.0;
    /// 8 or 4: the binary tree is collapsed into 8- or 4-wide nodes whose boxes are tested
    /// four (SSE) or eight (AVX2, see `avx2`) at a time (8, the default, measured about 10% faster
    /// than 4 on the armadillo); 2: the binary tree is traversed as built.
    int width = 8;
    /// Build large subtrees on several threads (oneTBB); the tree, and its nodes' order in
    /// memory, are the same either way.
    bool parallel = true;
    /// For TriangleSet<float> sets: the BVH keeps its own copy of each leaf's triangles, four
    /// to a block in leaf order (BvhTriangleBlock), and tests a block's four at once with SIMD,
    /// as Embree's Triangle4 leaves do; the SAH then prices a leaf by its blocks. Ignored for
    /// other sets, whose leaves name their primitives and test them one at a time.
    bool triangle_blocks = true;
    /// Test 8-wide nodes with AVX2 (one 8-lane slab test) when the CPU has it, as `build`
    /// checks. The AVX2 and SSE code do the same float operations lane by lane, so answers and
    /// counters are the same either way; false forces the SSE code.
    bool avx2 = true;
};

/// The configuration of every structure, so one value can be handed to the factory.
struct AcceleratorConfig {
    BruteForceConfig brute_force;
    GridConfig grid;
    HierarchicalGridConfig hierarchical_grid;
    RayClassificationConfig ray_classification;
    BvhConfig bvh;
};

}  // namespace csgrt
