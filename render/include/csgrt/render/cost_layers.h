#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "csgrt/csg/scene.h"
#include "csgrt/render/image.h"
#include "csgrt/render/renderer.h"

namespace csgrt {

/// A copy of `scene` in which every structure (the top level's, each compound's, each mesh's)
/// is `structure`, built anew and committed: what the scene would cost if it used that one
/// structure throughout. Instances, booleans, painted shapes, compounds and meshes are rebuilt
/// around their
/// rebuilt children; leaves, and shapes with no structure below them, are shared with `scene`,
/// and a shape shared within `scene` stays shared. A mesh is rebuilt from its stored triangles
/// (for a float mesh, the float corners: the same geometry). Materials, lights and camera are
/// copied. Walks the trees without recursion, so deep instance chains are fine. Throws
/// InvalidParameter for a name make_accelerator does not know.
Scene with_every_structure(const Scene& scene, std::string_view structure);

/// The summed build times of every structure in the committed `scene`: the top level's and
/// those of the compounds and meshes under it, each distinct shape once.
double structure_build_milliseconds(const Scene& scene);

/// The sum of a layer's total cost over its pixels (exact: the pixels hold integer counts).
std::uint64_t cost_sum(const CostLayer& layer);

/// The cost layer of one structure: `scene` rebuilt with with_every_structure(scene,
/// structure), its build time, render_cost's channels at `settings`' size (centre rays only:
/// no shading, no shadow or secondary ray), and the wall time of that trace.
CostLayer cost_layer(const Scene& scene, const RenderSettings& settings,
                     std::string_view structure);

/// One cost layer per structure name in `structures` (accelerator_names() for --cost-all), in
/// that order.
std::vector<CostLayer> cost_layers(const Scene& scene, const RenderSettings& settings,
                                   const std::vector<std::string_view>& structures);

}  // namespace csgrt
