// The csgrt Python module: batch ray and point queries on NumPy arrays (docs/python.md).

#include <pybind11/pybind11.h>

#include "arrays.h"
#include "bindings.h"
#include "csgrt/mesh/mesh_io.h"
#include "csgrt/core/error.h"
#include "csgrt/csg/scene_file.h"

PYBIND11_MODULE(csgrt, m) {
    namespace py = pybind11;
    m.doc() = R"doc(
csgrt: exact ray queries on triangle meshes, analytic shapes and CSG solids, many rays per call.

- RaycastingScene: triangle meshes with Open3D's RaycastingScene names (cast_rays,
  test_occlusions, count_intersections, list_intersections, compute_occupancy,
  compute_closest_points, compute_distance, compute_signed_distance).
- Scene, load_scene: any csgrt scene (CSG, analytic shapes, instances, meshes) with the same
  ray queries (and each hit's material), point membership, render() and the cost of every
  structure (cost_layers).
- Shapes: shape() and one function per scene-file type (sphere, box, torus, ...), union,
  intersection, difference, complement, painted (an operand's own material), compound,
  instance, mesh, load_mesh.

Inputs are NumPy arrays, float32 or float64 used in place when C-contiguous; every query
releases the GIL. See docs/python.md.
)doc";
    m.attr("__version__") = "0.1.0";
    // Errors in files are values the caller gave: ValueError subclasses naming the place.
    static py::exception<csgrt::SceneError> scene_error(m, "SceneError", PyExc_ValueError);
    static py::exception<csgrt::MeshError> mesh_error(m, "MeshError", PyExc_ValueError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const csgrt::SceneError& e) {
            scene_error(e.what());
        } catch (const csgrt::MeshError& e) {
            mesh_error(e.what());
        }
    });
    // Internal, for the tests: the bytes of dead result arrays kept for the next results.
    m.def("_kept_result_memory", &csgrt::python::kept_result_memory);
    csgrt::python::bind_raycasting_scene(m);
    csgrt::python::bind_scene(m);
}
