#pragma once

#include <memory>
#include <span>
#include <string_view>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/brute_force.h"
#include "csgrt/accel/bvh.h"
#include "csgrt/accel/hierarchical_grid.h"
#include "csgrt/accel/ray_classification.h"
#include "csgrt/accel/regular_grid.h"

namespace csgrt {

/// The configuration of every structure, so one value can be handed to the factory.
struct AcceleratorConfig {
    BruteForceConfig brute_force;
    GridConfig grid;
    HierarchicalGridConfig hierarchical_grid;
    RayClassificationConfig ray_classification;
    BvhConfig bvh;
};

/// The names `make_accelerator` accepts, in the order the benchmark reports them.
std::span<const std::string_view> accelerator_names();

/// Builds the structure called `name` over `set` (which must outlive it). The only place a
/// structure is chosen at run time. Throws InvalidParameter for an unknown name, listing the
/// known ones. Instantiated for TriangleSet<float>, TriangleSet<double> and ShapeSet.
template <class Set>
std::unique_ptr<Accelerator<Set>> make_accelerator(std::string_view name, const Set& set,
                                                   const AcceleratorConfig& config = {});

}  // namespace csgrt
