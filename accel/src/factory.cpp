#include "csgrt/accel/factory.h"

#include <algorithm>
#include <array>
#include <string>
#include <tuple>

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

/// One registered structure: its factory name (the structure's kName) and how to build it over
/// any set from its part of the AcceleratorConfig.
template <template <class> class Structure, auto kConfigField>
struct Registered {
    static constexpr std::string_view kName = Structure<ShapeSet>::kName;
    template <class Set>
    static std::unique_ptr<Accelerator<Set>> build(const Set& set,
                                                   const AcceleratorConfig& config) {
        auto structure = std::make_unique<Structure<Set>>();
        structure->build(set, config.*kConfigField);
        return structure;
    }
};

/// Every structure, one line each, in the order the benchmark reports them.
using Registry = std::tuple<Registered<BruteForce, &AcceleratorConfig::brute_force>,
                            Registered<RegularGrid, &AcceleratorConfig::grid>,
                            Registered<HierarchicalGrid, &AcceleratorConfig::hierarchical_grid>,
                            Registered<RayClassification, &AcceleratorConfig::ray_classification>,
                            Registered<Bvh, &AcceleratorConfig::bvh>>;

template <class... Entries>
constexpr std::array<std::string_view, sizeof...(Entries)> names_of(const std::tuple<Entries...>*) {
    return {Entries::kName...};
}
constexpr auto kNames = names_of(static_cast<const Registry*>(nullptr));

template <class Set, class... Entries>
std::unique_ptr<Accelerator<Set>> build_named(std::string_view name, const Set& set,
                                              const AcceleratorConfig& config,
                                              const std::tuple<Entries...>*) {
    std::unique_ptr<Accelerator<Set>> structure;
    ((name == Entries::kName && (structure = Entries::template build<Set>(set, config))) || ...);
    return structure;
}

}  // namespace

std::span<const std::string_view> accelerator_names() {
    return kNames;
}

template <class Set>
std::unique_ptr<Accelerator<Set>> make_accelerator(std::string_view name, const Set& set,
                                                   const AcceleratorConfig& config) {
    if (auto structure = build_named(name, set, config, static_cast<const Registry*>(nullptr)))
        return structure;
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
