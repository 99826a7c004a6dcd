#pragma once

#include <memory>

#include "csgrt/core/plane.h"

namespace csgrt::test {

/// The unbounded ground y = height, facing +y: an open surface no structure can bound.
inline std::shared_ptr<const Shape> ground_plane(double height = 0.0) {
    return std::make_shared<Plane>(Point3(0, height, 0), Normal3(0, 1, 0));
}

/// A CompoundConfig or a SceneConfig (`Config`) that asks for the structure `name`.
template <class Config>
Config structure_named(const char* name) {
    Config config;
    config.accelerator = name;
    return config;
}

}  // namespace csgrt::test
