#pragma once

#include <pybind11/pybind11.h>

namespace csgrt::python {

/// Each file of the module adds its classes and functions to `m`.
void bind_raycasting_scene(pybind11::module_& m);
void bind_scene(pybind11::module_& m);

}  // namespace csgrt::python
