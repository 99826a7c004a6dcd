// csgrt.Scene and csgrt.Shape: the whole csgrt scene from Python (analytic shapes, part
// objects, booleans, instances, meshes, scene files), the same queries as RaycastingScene, and
// the renderer's AOVs as NumPy arrays.

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <filesystem>
#include <mutex>

#include "bindings.h"
#include "csgrt/accel/factory.h"
#include "csgrt/mesh/mesh.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/complement.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/scene_file.h"
#include "queries.h"
#include "scene.h"

namespace csgrt::python {

namespace {

std::vector<std::shared_ptr<const Shape>> shapes_of(const py::args& args, const char* what) {
    std::vector<std::shared_ptr<const Shape>> shapes;
    for (std::size_t i = 0; i < args.size(); ++i) {
        shapes.push_back(
            shape_of(py::object(args[i]), std::string(what) + "[" + std::to_string(i) + "]"));
    }
    return shapes;
}

/// A scene node as the scene file writes it (docs/scene-format.md), through the file's own
/// reader: every shape type and every parameter check is the file's, with its messages.
PyShape shape_from_node(const std::string& type, const py::kwargs& params) {
    using namespace pybind11::literals;
    py::dict node;
    node["type"] = type;
    for (const auto& [key, value] : params) node[key] = value;
    py::dict document;
    document["objects"] = py::make_tuple(node);
    // NumPy arrays and scalars become lists and numbers.
    const py::object to_plain = py::module_::import("builtins").attr("eval")(
        "lambda o: o.tolist() if hasattr(o, 'tolist') else str(o)");
    const std::string text =
        py::module_::import("json").attr("dumps")(document, "default"_a = to_plain)
            .cast<std::string>();
    const Scene scene = load_scene_from_string(text, "csgrt." + type,
                                               std::filesystem::current_path());
    if (scene.objects().size() != 1) {
        throw py::value_error(type + ": makes " + std::to_string(scene.objects().size()) +
                              " objects; wrap them in csgrt.compound(...)");
    }
    return PyShape{scene.objects()[0].shape};
}

TriangleMeshData mesh_data(const py::handle& vertices_object, const py::handle& triangles_object) {
    const FloatInput vertices = float_input(vertices_object, "vertices", 3, "(N, 3)");
    const py::array triangles_array = py::array::ensure(triangles_object);
    if (!triangles_array ||
        (triangles_array.dtype().kind() != 'i' && triangles_array.dtype().kind() != 'u') ||
        triangles_array.ndim() != 2 || triangles_array.shape(1) != 3) {
        throw py::value_error("triangles: expected an integer array of shape (M, 3), got " +
                              (triangles_array ? shape_text(triangles_array) + " " +
                                                     std::string(py::str(triangles_array.dtype()))
                                               : std::string("no array")));
    }
    const auto indices = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::
        ensure(triangles_array);
    TriangleMeshData data;
    for (std::size_t i = 0; i < vertices.count; ++i) {
        data.vertices.push_back(vertices.is_float32 ? point_arrays<float>(vertices)[i]
                                                    : point_arrays<double>(vertices)[i]);
    }
    const std::int64_t* index = indices.data();
    for (py::ssize_t t = 0; t < indices.shape(0); ++t) {
        std::array<std::uint32_t, 3> triangle{};
        for (int k = 0; k < 3; ++k) {
            const std::int64_t v = index[3 * t + k];
            if (v < 0 || v >= static_cast<std::int64_t>(vertices.count)) {
                throw py::value_error("triangles: row " + std::to_string(t) +
                                      " refers to vertex " + std::to_string(v) + ", but there are " +
                                      std::to_string(vertices.count) + " vertices");
            }
            triangle[k] = static_cast<std::uint32_t>(v);
        }
        data.triangles.push_back(triangle);
    }
    return data;
}

}  // namespace

void bind_scene(py::module_& m) {
    using namespace pybind11::literals;
    py::class_<PyShape>(m, "Shape", R"doc(
A csgrt shape: an analytic primitive, part object, mesh, boolean, compound or instance.
Immutable and shareable: the same shape may be added to several scenes and nested in several
booleans. Made by csgrt.shape(), the functions named after each shape type (csgrt.sphere,
csgrt.box, ...), csgrt.union / intersection / difference, csgrt.compound, csgrt.instance,
csgrt.mesh and csgrt.load_mesh.
)doc")
        .def_property_readonly(
            "kind", [](const PyShape& s) { return std::string(s.shape->kind()); },
            "The shape's kind: 'sphere', 'difference', 'mesh', 'instance', ...")
        .def_property_readonly(
            "is_solid", [](const PyShape& s) { return s.shape->is_solid(); },
            "Whether the shape is a closed solid (a boolean operand, with inside and outside).")
        .def_property_readonly(
            "bounds",
            [](const PyShape& s) {
                const Aabb box = s.shape->bounds();
                return py::make_tuple(Eigen::Vector3d(box.lower), Eigen::Vector3d(box.upper));
            },
            "(lower, upper) corners of the shape's bounding box (infinite for planes).")
        .def(
            "contains",
            [](const PyShape& s, const py::object& point) {
                return s.shape->contains(vector3(point, "point"));
            },
            "point"_a, "Whether the point (3 numbers) is inside the solid (False for surfaces).")
        .def("__repr__", [](const PyShape& s) {
            return "<csgrt.Shape " + std::string(s.shape->kind()) + ">";
        });

    m.def("shape", &shape_from_node, "type"_a, R"doc(
Makes a shape from its scene-file type and keyword parameters, exactly as a scene file's node
(docs/scene-format.md): lengths in the scene's units, angles in degrees, points and vectors as
3 numbers (lists or arrays), an optional ``transform`` list. For example
``csgrt.shape("part_sphere", radius=1, phi_max=270)``. Parameters the type does not take, or
values it rejects, raise ValueError naming the parameter.
)doc");
    for (const std::string_view type : scene_shape_types()) {
        if (type == "union" || type == "intersection" || type == "difference" ||
            type == "compound" || type == "mesh" || type == "ref" || type == "grid" ||
            type == "not" || type == "array") {
            // Booleans, the complement ("not" is a Python keyword: csgrt.complement),
            // compounds and meshes take shapes or arrays (bound below); a scene file's
            // references, grids and arrays of copies name definitions, which Python holds as
            // variables (and copies as a loop).
            continue;
        }
        const std::string name(type);
        const std::string doc = "Makes a " + name + ": csgrt.shape('" + name +
                                "', **params), with the scene file's parameter names "
                                "(docs/scene-format.md, docs/python.md).";
        m.def(
            name.c_str(),
            [name](const py::kwargs& params) { return shape_from_node(name, params); },
            doc.c_str());
    }
    m.def(
        "union", [](const py::args& args) { return PyShape{make_union(shapes_of(args, "operands"))}; },
        "The union of two or more solids (a balanced tree of CSG unions).");
    m.def(
        "intersection",
        [](const py::args& args) { return PyShape{make_intersection(shapes_of(args, "operands"))}; },
        "The intersection of two or more solids.");
    m.def(
        "difference",
        [](const py::object& first, const py::args& args) {
            return PyShape{make_difference(shape_of(first, "first"), shapes_of(args, "subtracted"))};
        },
        "first"_a, "The first solid minus every other one: difference(a, b, c) = a - (b | c).");
    m.def(
        "complement",
        [](const py::object& operand) {
            return PyShape{std::make_shared<Complement>(shape_of(operand, "operand"))};
        },
        "operand"_a,
        "Everything outside a solid (the scene file's \"not\"), itself a solid: "
        "intersection(a, complement(b)) is difference(a, b).");
    m.def(
        "accelerator_names",
        [] {
            std::vector<std::string> names;
            for (const std::string_view name : accelerator_names()) names.emplace_back(name);
            return names;
        },
        "The structure names commit(), compound(), mesh() and cost_layers() take, in the "
        "order `csgrt render --cost-all` draws them.");
    m.def(
        "painted",
        [](const py::object& shape, std::uint32_t material) {
            if (material > kMaxPaintedMaterial) {
                throw py::value_error("material: expected an index up to " +
                                      std::to_string(kMaxPaintedMaterial) + ", got " +
                                      std::to_string(material));
            }
            return PyShape{std::make_shared<Painted>(shape_of(shape, "shape"), material)};
        },
        "shape"_a, "material"_a, R"doc(
The shape with a material of its own (the scene file's ``material`` on a node below an object):
its hits carry ``material`` (an index from Scene.add_material) through booleans, instances and
compounds, the innermost painted shape winning, and surfaces under no painted shape take their
object's. A cut surface belongs to the operand that cut it, so difference(painted(box, 1),
painted(ball, 2)) shows material 2 inside the bite. Scene.commit() checks the index.
)doc");
    m.def(
        "compound",
        [](const py::list& children, const std::string& accelerator) {
            std::vector<std::shared_ptr<const Shape>> shapes;
            for (std::size_t i = 0; i < children.size(); ++i) {
                shapes.push_back(
                    shape_of(py::object(children[i]), "children[" + std::to_string(i) + "]"));
            }
            CompoundConfig config;
            config.accelerator = accelerator;
            return PyShape{std::make_shared<Compound>(std::move(shapes), config)};
        },
        "children"_a, "accelerator"_a = "auto",
        "A plain group of shapes with a structure over them (no boolean): the nearest hit of "
        "any child. accelerator: 'auto' or a structure name ('bvh', 'grid', ...).");
    m.def(
        "instance",
        [](const py::object& shape, const py::object& matrix) {
            const auto array =
                py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(matrix);
            if (!array || array.ndim() != 2 || array.shape(1) != 4 ||
                (array.shape(0) != 3 && array.shape(0) != 4)) {
                throw py::value_error("matrix: expected an array of shape (4, 4) or (3, 4), got " +
                                      (array ? shape_text(array) : std::string("no array")));
            }
            Eigen::Matrix4d m4 = Eigen::Matrix4d::Identity();
            for (py::ssize_t r = 0; r < array.shape(0); ++r) {
                for (int c = 0; c < 4; ++c) m4(r, c) = array.at(r, c);
            }
            return PyShape{std::make_shared<Instance>(shape_of(shape, "shape"),
                                                      Transform::from_matrix(m4))};
        },
        "shape"_a, "matrix"_a,
        "The shape under an affine transform: matrix (4, 4) or (3, 4) maps the shape's space to "
        "the world (world_from_object), points as column vectors. Rays are not renormalised, "
        "so t is the same in both spaces.");
    m.def(
        "mesh",
        [](const py::handle& vertices, const py::handle& triangles, bool double_precision,
           const std::string& accelerator) {
            MeshConfig config;
            config.double_precision = double_precision;
            if (!accelerator.empty()) config.accelerator = accelerator;
            auto data = mesh_data(vertices, triangles);
            py::gil_scoped_release release;
            return PyShape{std::make_shared<Mesh>(std::move(data), config)};
        },
        "vertices"_a, "triangles"_a, "double_precision"_a = false, "accelerator"_a = "",
        "A triangle mesh shape from arrays: vertices (N, 3), triangles (M, 3) integer indices. "
        "Validated as mesh files are (degenerate triangles dropped, closed shells oriented "
        "outward, docs/meshes.md): a closed mesh is a solid. Triangles in float32 unless "
        "double_precision. accelerator: the structure over the triangles ('bvh', 'grid', ...; "
        "empty: the mesh default).");
    m.def(
        "read_mesh",
        [](const std::string& path) {
            TriangleMeshData data = [&] {
                py::gil_scoped_release release;
                TriangleMeshData loaded = load_mesh(path);
                return loaded;
            }();
            py::array_t<double> vertices(
                std::vector<py::ssize_t>{static_cast<py::ssize_t>(data.vertices.size()), 3});
            py::array_t<std::uint32_t> triangles(
                std::vector<py::ssize_t>{static_cast<py::ssize_t>(data.triangles.size()), 3});
            double* v = vertices.mutable_data();
            for (std::size_t i = 0; i < data.vertices.size(); ++i) {
                for (int k = 0; k < 3; ++k) v[3 * i + k] = data.vertices[i][k];
            }
            std::uint32_t* t = triangles.mutable_data();
            for (std::size_t i = 0; i < data.triangles.size(); ++i) {
                for (int k = 0; k < 3; ++k) t[3 * i + k] = data.triangles[i][k];
            }
            return py::make_tuple(vertices, triangles);
        },
        "path"_a,
        "Reads an OFF, OBJ, PLY or STL file with csgrt's loader and validation (docs/meshes.md: "
        "degenerate triangles dropped, closed shells oriented outward) and returns (vertices "
        "(N, 3) float64, triangles (M, 3) uint32), e.g. for RaycastingScene.add_triangles. "
        "Raises csgrt.MeshError naming the file and what is wrong.");
    m.def(
        "load_mesh",
        [](const std::string& path, bool double_precision) {
            MeshConfig config;
            config.double_precision = double_precision;
            py::gil_scoped_release release;
            return PyShape{Mesh::load(path, config)};
        },
        "path"_a, "double_precision"_a = false,
        "A mesh shape from an OFF, OBJ, PLY or STL file (docs/meshes.md). Raises "
        "csgrt.MeshError naming the file and what is wrong.");

    py::class_<PyScene> scene(m, "Scene", R"doc(
A csgrt scene: objects (any csgrt.Shape: analytic solids, CSG trees, instances, meshes),
materials, lights and a camera. Add objects, call commit(), then query: the queries have
RaycastingScene's names and results (geometry_ids are object ids) and work on every kind of
shape. Objects added after commit() are seen by queries after the next commit().
)doc");
    scene.def(py::init<>(), "An empty scene with the default camera and material 0 ('default').");
    scene.def("add_object", &PyScene::add_object, "shape"_a, "material"_a = 0, "name"_a = "",
              "Adds a shape as a top-level object; returns its object id. material: an index "
              "from add_material or a material name.");
    scene.def("add_material", &PyScene::add_material, "name"_a, "albedo"_a,
              "Adds a Lambertian material (linear RGB albedo in [0, 1]); returns its index.");
    scene.def("add_point_light", &PyScene::add_point_light, "position"_a, "intensity"_a = 100.0,
              "A point light (intensity: a number or RGB, radiance times squared distance).");
    scene.def("add_directional_light", &PyScene::add_directional_light, "direction"_a,
              "radiance"_a = 1.0, "Light arriving along `direction` from infinitely far away.");
    scene.def("set_camera", &PyScene::set_camera, "position"_a, "look_at"_a,
              "up"_a = py::make_tuple(0.0, 1.0, 0.0), "fov"_a = 40.0,
              "projection"_a = "pinhole", "height"_a = 2.0,
              "The camera render() looks through: fov is the vertical field of view in "
              "degrees (pinhole), height the view's height (orthographic).");
    scene.def("commit", &PyScene::commit, "accelerator"_a = "auto",
              "Builds the bounds and the structure over the objects (accelerator: 'auto' or "
              "a structure name) and makes this state the one queries see.");
    scene.def_property_readonly("object_count", &PyScene::object_count,
                                "Objects added so far.");
    scene.def_property_readonly(
        "bounds",
        [](const PyScene& self) {
            const Aabb box = self.committed()->bounds();
            return py::make_tuple(Eigen::Vector3d(box.lower), Eigen::Vector3d(box.upper));
        },
        "(lower, upper) of the committed scene's bounded objects.");
    scene.def_property_readonly(
        "accelerator",
        [](const PyScene& self) { return std::string(self.committed()->accelerator_name()); },
        "The structure commit() chose over the objects.");

    const std::string rays_doc = ray_query_doc();
    QueryDocs docs;
    docs.cast_rays =
        "The nearest hit of every ray, as RaycastingScene.cast_rays: t_hit, geometry_ids "
        "(object ids), primitive_ids (the leaf's own sub-primitive: triangle, box face, cap), "
        "primitive_uvs (the surface's uv), primitive_normals (geometric, outward for solids) "
        "and, when asked for in outputs, shading_normals (interpolated on meshes).\n" +
        rays_doc;
    docs.test_occlusions =
        "Whether anything is hit in [tnear, tfar] along each ray (bool array).\n" + rays_doc;
    docs.count_intersections =
        "How many surfaces each ray crosses in [tnear, tfar] (int32): its successive nearest "
        "hits, each searched just beyond the last, so coincident surfaces count once.\n" +
        rays_doc;
    docs.list_intersections =
        "Every crossing, as RaycastingScene.list_intersections; `entering` is True where the "
        "ray arrives on the side the surface's normal points to (into a solid).\n" +
        rays_doc;
    docs.compute_occupancy =
        "1.0 where a point is inside a solid object (CSG trees, analytic solids, closed "
        "meshes; each solid's own exact membership test), 0.0 elsewhere (float32).\n"
        "nsamples: must be 1.\n" +
        point_query_doc();
    bind_queries(
        scene,
        [](const PyScene& self, const auto& query) {
            const auto committed = self.committed();
            return query(*committed);
        },
        docs);
    bind_rendering(scene);

    m.def(
        "load_scene",
        [](const std::string& path, const std::string& accelerator) {
            Scene loaded = [&] {
                py::gil_scoped_release release;
                return csgrt::load_scene(path);
            }();
            auto loaded_scene = std::make_unique<PyScene>(std::move(loaded));
            loaded_scene->commit(accelerator);
            return loaded_scene;
        },
        "path"_a, "accelerator"_a = "auto",
        "Reads a JSON scene file (docs/scene-format.md) and commits it: a Scene ready for "
        "queries and render(). Raises csgrt.SceneError naming the file, the place in it and "
        "what was expected.");
}

}  // namespace csgrt::python
