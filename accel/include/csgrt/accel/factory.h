#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"

namespace csgrt {

/// The names `make_accelerator` accepts, in the order the benchmark reports them.
std::span<const std::string_view> accelerator_names();

/// Builds the structure called `name` over `set` (which must outlive it). The only place a
/// structure is chosen at run time. Throws InvalidParameter for an unknown name, listing the
/// known ones. Instantiated for TriangleSet<float>, TriangleSet<double> and ShapeSet.
template <class Set>
std::unique_ptr<Accelerator<Set>> make_accelerator(std::string_view name, const Set& set,
                                                   const AcceleratorConfig& config = {});

/// At most this many bounded members are tested directly under "auto".
inline constexpr std::size_t kHandfulOfMembers = 4;

/// The structure "auto" picks for `count` bounded members (a compound's children, a scene's
/// objects): "brute" for at most kHandfulOfMembers (testing a handful directly costs less than
/// traversing a hierarchy over them), otherwise "bvh" when the factory knows it, else "brute".
/// `reason` receives one sentence saying which rule applied (docs/scene.md).
std::string choose_accelerator(std::size_t count, std::string& reason);

}  // namespace csgrt
