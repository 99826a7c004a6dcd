#pragma once

#include <string_view>

#include "csgrt/accel/accelerator_config.h"

namespace csgrt {

/// A shape with an acceleration structure of its own (a compound over its children) that can
/// leave building it to the scene it is committed in: Scene::commit(config) walks its objects'
/// trees and hands each such shape, once, the configuration commit was given, so a scene's
/// SceneConfig reaches the structures below its top level. A shape implements it beside Shape;
/// one whose structure is built already (by its constructor, an earlier commit or a first
/// query) ignores the call.
class BuiltAtCommit {
public:
    /// Builds the structure unless it is built already: `accelerator` (the scene's structure
    /// name) where the shape's own choice is "auto", and `config` for every structure's
    /// parameters. Thread-safe; queries after it see the structure.
    virtual void build_at_commit(std::string_view accelerator,
                                 const AcceleratorConfig& config) const = 0;

protected:
    ~BuiltAtCommit() = default;
};

}  // namespace csgrt
