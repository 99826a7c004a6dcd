#include "csgrt/accel/factory.h"

#include <algorithm>
#include <array>
#include <string>

#include "csgrt/accel/brute_force.h"
#include "csgrt/accel/bvh.h"
#include "csgrt/accel/hierarchical_grid.h"
#include "csgrt/accel/ray_classification.h"
#include "csgrt/accel/regular_grid.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"

namespace csgrt {

namespace {
constexpr std::array<std::string_view, 5> kNames = {"brute", "grid", "hgrid", "rayclass", "bvh"};

template <class Structure, class Set, class Config>
std::unique_ptr<Accelerator<Set>> build(const Set& set, const Config& config) {
    auto structure = std::make_unique<Structure>();
    structure->build(set, config);
    return structure;
}
}  // namespace

std::span<const std::string_view> accelerator_names() {
    return kNames;
}

template <class Set>
std::unique_ptr<Accelerator<Set>> make_accelerator(std::string_view name, const Set& set,
                                                   const AcceleratorConfig& config) {
    if (name == "brute") return build<BruteForce<Set>>(set, config.brute_force);
    if (name == "grid") return build<RegularGrid<Set>>(set, config.grid);
    if (name == "hgrid") return build<HierarchicalGrid<Set>>(set, config.hierarchical_grid);
    if (name == "rayclass") return build<RayClassification<Set>>(set, config.ray_classification);
    if (name == "bvh") return build<Bvh<Set>>(set, config.bvh);
    std::string known;
    for (std::string_view n : kNames) known.append(known.empty() ? "" : ", ").append(n);
    require(false, "make_accelerator", "name", "one of " + known, std::string(name));
    return nullptr;
}

std::string choose_accelerator(std::size_t count, std::string& reason) {
    if (count <= kHandfulOfMembers) {
        reason = std::to_string(count) + " bounded member" + (count == 1 ? "" : "s") +
                 " (at most " + std::to_string(kHandfulOfMembers) +
                 "): tested directly, no hierarchy";
        return "brute";
    }
    const auto names = accelerator_names();
    if (std::find(names.begin(), names.end(), "bvh") != names.end()) {
        reason = std::to_string(count) + " bounded members: a BVH over their boxes";
        return "bvh";
    }
    reason = std::to_string(count) +
             " bounded members: brute force, because this build has no BVH (\"bvh\" is not "
             "registered with make_accelerator)";
    return "brute";
}

template std::unique_ptr<Accelerator<TriangleSet<float>>> make_accelerator(
    std::string_view, const TriangleSet<float>&, const AcceleratorConfig&);
template std::unique_ptr<Accelerator<TriangleSet<double>>> make_accelerator(
    std::string_view, const TriangleSet<double>&, const AcceleratorConfig&);
template std::unique_ptr<Accelerator<ShapeSet>> make_accelerator(std::string_view, const ShapeSet&,
                                                                 const AcceleratorConfig&);

}  // namespace csgrt
