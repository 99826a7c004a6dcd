// csgrt.RaycastingScene: Open3D's RaycastingScene names over csgrt's BVH and batch queries.

#include <mutex>

#include <pybind11/eigen.h>

#include <Eigen/Geometry>

#include "bindings.h"
#include "csgrt/accel/factory.h"
#include "csgrt/mesh/mesh.h"
#include "queries.h"

namespace csgrt::python {

namespace {

/// Everything the queries read, rebuilt whole by add_triangles and never changed after: a
/// query holds the snapshot it started with, so adding from one thread while others query is
/// safe, and queries never wait for a build.
struct TriangleScene {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into `vertices`
    std::vector<std::uint32_t> object_of_triangle;
    std::vector<std::uint32_t> first_triangle;
    TriangleSet<float> set;
    std::unique_ptr<Accelerator<TriangleSet<float>>> structure;
    std::unique_ptr<ClosestPointTree<float>> closest_points;

    void build() {
        set = TriangleSet<float>(vertices, triangles);
        structure = make_accelerator("bvh", set);
        closest_points = std::make_unique<ClosestPointTree<float>>(set);
    }
    TriangleStructure<float> view() const {
        return {&set, structure.get(), closest_points.get(), object_of_triangle, first_triangle};
    }
};

class RaycastingScene {
public:
    RaycastingScene() {
        auto empty = std::make_shared<TriangleScene>();
        empty->build();
        current_ = std::move(empty);
    }

    std::uint32_t add_triangles(const py::handle& vertices_object,
                                const py::handle& triangles_object) {
        const FloatInput vertices = float_input(vertices_object, "vertices", 3, "(N, 3)");
        if (vertices.leading.size() != 1) {
            throw py::value_error("vertices: expected an array of shape (N, 3), got " +
                                  shape_text(vertices.array));
        }
        py::array triangles_array = py::array::ensure(triangles_object);
        if (!triangles_array || (triangles_array.dtype().kind() != 'i' &&
                                 triangles_array.dtype().kind() != 'u')) {
            throw py::value_error(
                "triangles: expected an integer array of shape (M, 3), got " +
                (triangles_array ? "dtype " + std::string(py::str(triangles_array.dtype()))
                                 : std::string("something that is not an array")));
        }
        if (triangles_array.ndim() != 2 || triangles_array.shape(1) != 3) {
            throw py::value_error("triangles: expected an array of shape (M, 3), got " +
                                  shape_text(triangles_array));
        }
        const auto indices =
            py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(
                triangles_array);
        std::vector<Eigen::Vector3d> new_vertices(vertices.count);
        for (std::size_t i = 0; i < vertices.count; ++i) {
            const Eigen::Vector3d v =
                vertices.is_float32 ? point_arrays<float>(vertices)[i]
                                    : point_arrays<double>(vertices)[i];
            if (!is_finite(v)) {
                throw py::value_error("vertices: row " + std::to_string(i) +
                                      " is not finite");
            }
            new_vertices[i] = v;
        }
        const std::int64_t* index = indices.data();
        const auto triangle_count = static_cast<std::size_t>(indices.shape(0));
        for (std::size_t k = 0; k < 3 * triangle_count; ++k) {
            if (index[k] < 0 || index[k] >= static_cast<std::int64_t>(vertices.count)) {
                throw py::value_error("triangles: row " + std::to_string(k / 3) +
                                      " refers to vertex " + std::to_string(index[k]) +
                                      ", but there are " + std::to_string(vertices.count) +
                                      " vertices");
            }
        }
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> writer(writer_mutex_);
        const std::shared_ptr<const TriangleScene> old = snapshot();
        auto next = std::make_shared<TriangleScene>();
        next->vertices = old->vertices;
        next->triangles = old->triangles;
        next->object_of_triangle = old->object_of_triangle;
        next->first_triangle = old->first_triangle;
        const auto id = static_cast<std::uint32_t>(next->first_triangle.size());
        const auto base = static_cast<std::uint32_t>(next->vertices.size());
        next->first_triangle.push_back(static_cast<std::uint32_t>(next->triangles.size()));
        next->vertices.insert(next->vertices.end(), new_vertices.begin(), new_vertices.end());
        for (std::size_t t = 0; t < triangle_count; ++t) {
            next->triangles.push_back({base + static_cast<std::uint32_t>(index[3 * t]),
                                       base + static_cast<std::uint32_t>(index[3 * t + 1]),
                                       base + static_cast<std::uint32_t>(index[3 * t + 2])});
            next->object_of_triangle.push_back(id);
        }
        next->build();
        std::lock_guard<std::mutex> publish(pointer_mutex_);
        current_ = std::move(next);
        return id;
    }

    std::shared_ptr<const TriangleScene> snapshot() const {
        std::lock_guard<std::mutex> lock(pointer_mutex_);
        return current_;
    }

    std::size_t geometry_count() const { return snapshot()->first_triangle.size(); }
    std::size_t triangle_count() const { return snapshot()->triangles.size(); }

private:
    std::mutex writer_mutex_;
    mutable std::mutex pointer_mutex_;
    std::shared_ptr<const TriangleScene> current_;
};

template <class Real>
py::dict closest_points_as(const TriangleStructure<float>& target, const FloatInput& points,
                           const BatchConfig& config) {
    auto point = output<Real>(points.leading, {3});
    auto geometry = output<std::uint32_t>(points.leading);
    auto primitive = output<std::uint32_t>(points.leading);
    auto uv = output<Real>(points.leading, {2});
    auto normal = output<Real>(points.leading, {3});
    ClosestPointOutputs<Real> outputs;
    outputs.point = span_of(point);
    outputs.object_id = span_of(geometry);
    outputs.primitive_id = span_of(primitive);
    outputs.uv = span_of(uv);
    outputs.normal = span_of(normal);
    {
        py::gil_scoped_release release;
        closest_points(target, point_arrays<Real>(points), outputs, config);
    }
    return named_results({{"points", point},
                          {"geometry_ids", geometry},
                          {"primitive_ids", primitive},
                          {"primitive_uvs", uv},
                          {"primitive_normals", normal}});
}

template <class Real>
py::array_t<Real> distance_as(const TriangleStructure<float>& target, const FloatInput& points,
                              bool signed_distance, const BatchConfig& config) {
    auto distance = output<Real>(points.leading);
    ClosestPointOutputs<Real> outputs;
    if (signed_distance) {
        outputs.signed_distance = span_of(distance);
    } else {
        outputs.distance = span_of(distance);
    }
    py::gil_scoped_release release;
    closest_points(target, point_arrays<Real>(points), outputs, config);
    return distance;
}

/// compute_distance and compute_signed_distance: the points' (signed) distances to the nearest
/// triangle in the points' precision, the arguments checked in the order they are given.
py::array distances(const RaycastingScene& self, const py::handle& points_object, int nthreads,
                    int nsamples, bool signed_distance) {
    const FloatInput points = float_input(points_object, "query_points", 3, "(..., 3)");
    check_samples(nsamples);
    const BatchConfig config = batch_config(nthreads);
    const auto snapshot = self.snapshot();
    return points.is_float32
               ? py::array(distance_as<float>(snapshot->view(), points, signed_distance, config))
               : py::array(distance_as<double>(snapshot->view(), points, signed_distance, config));
}

py::array create_rays_pinhole(double fov_deg, const Eigen::Vector3d& center,
                              const Eigen::Vector3d& eye, const Eigen::Vector3d& up,
                              int width_px, int height_px) {
    if (!(fov_deg > 0.0 && fov_deg < 180.0)) {
        throw py::value_error("fov_deg: expected a horizontal field of view in (0, 180), got " +
                              std::to_string(fov_deg));
    }
    if (width_px <= 0 || height_px <= 0) {
        throw py::value_error("width_px, height_px: expected positive sizes, got " +
                              std::to_string(width_px) + " x " + std::to_string(height_px));
    }
    const Eigen::Vector3d forward = (center - eye).normalized();
    const Eigen::Vector3d right = forward.cross(up);
    if (!is_finite(forward) || !(right.norm() > 0.0) || !is_finite(right)) {
        throw py::value_error("center, eye, up: expected distinct eye and center and an up "
                              "vector not parallel to the view direction");
    }
    const Eigen::Vector3d x_axis = right.normalized();
    const Eigen::Vector3d y_axis = x_axis.cross(forward);  // up in the image
    const double half_width = std::tan(0.5 * fov_deg * kPi / 180.0);
    const double pixel = 2.0 * half_width / width_px;
    py::array_t<float> rays(std::vector<py::ssize_t>{height_px, width_px, 6});
    float* out = rays.mutable_data();
    for (int y = 0; y < height_px; ++y) {
        for (int x = 0; x < width_px; ++x) {
            // Through the pixel centre, x to the right and y down, as images are stored.
            const double sx = (x + 0.5) * pixel - half_width;
            const double sy = 0.5 * height_px * pixel - (y + 0.5) * pixel;
            const Eigen::Vector3d d = (forward + sx * x_axis + sy * y_axis).normalized();
            float* ray = out + 6 * (static_cast<std::size_t>(y) * width_px + x);
            for (int k = 0; k < 3; ++k) {
                ray[k] = static_cast<float>(eye[k]);
                ray[3 + k] = static_cast<float>(d[k]);
            }
        }
    }
    return rays;
}

}  // namespace

void bind_raycasting_scene(py::module_& m) {
    using namespace pybind11::literals;
    py::class_<RaycastingScene> scene(m, "RaycastingScene", R"doc(
Triangle meshes in one BVH, queried with many rays or points at once.

The names and results follow Open3D's ``open3d.t.geometry.RaycastingScene``, on NumPy arrays
instead of Open3D tensors: switching is a change of the import. Misses are reported as Open3D
reports them: ``t_hit`` = inf and the id ``RaycastingScene.INVALID_ID`` (2**32 - 1).

Triangles are stored in float32 and intersected with the watertight test (Woop et al. 2013):
a ray through a shared edge or vertex never slips between the triangles. Every query releases
the GIL and runs on ``nthreads`` threads with the same answers for any thread count; a query
started while another thread adds triangles sees the scene as it was when it started.
)doc");
    scene.attr("INVALID_ID") = py::int_(kNoIndex);
    scene.def(py::init<>(), "An empty scene: every ray misses until triangles are added.");
    scene.def("add_triangles", &RaycastingScene::add_triangles, "vertices"_a, "triangles"_a,
              R"doc(
Adds a triangle mesh and returns its geometry id (0, 1, 2, ... in the order of the calls).

vertices: array of shape (N, 3), float32 or float64, finite.
triangles: integer array of shape (M, 3) of indices into ``vertices``.

The structure over every mesh is rebuilt before this returns (there is no separate commit, as
in Open3D); primitive ids in results are the row of ``triangles``.
)doc");
    scene.def_property_readonly("geometry_count", &RaycastingScene::geometry_count,
                                "How many meshes add_triangles has added.");
    scene.def_property_readonly("triangle_count", &RaycastingScene::triangle_count,
                                "Triangles over all meshes.");

    const std::string rays_doc = ray_query_doc();
    const std::string points_doc = point_query_doc();
    QueryDocs docs;
    docs.cast_rays = R"doc(
The nearest hit of every ray. Returns a dict of arrays with the rays' leading shape:

- ``t_hit`` (...): the ray parameter of the hit, inf for a miss;
- ``geometry_ids`` (...), uint32: the mesh, INVALID_ID for a miss;
- ``primitive_ids`` (...), uint32: the triangle within its mesh, INVALID_ID for a miss;
- ``primitive_uvs`` (..., 2): barycentric coordinates of the triangle's 2nd and 3rd vertex;
- ``primitive_normals`` (..., 3): the triangle's unit normal (right-handed winding);
- ``shading_normals`` (..., 3), only when asked for in ``outputs``: the same for meshes.

Floating-point results have the rays' precision (float32 in, float32 out).
outputs: None for the five Open3D outputs, or a list of the names wanted; a query that asks
only for "t_hit" does only the traversal.
)doc" + rays_doc;
    docs.test_occlusions =
        "Whether anything is hit in [tnear, tfar] along each ray (shadow rays): a bool array "
        "of the rays' leading shape. Stops at the first hit found.\n" +
        rays_doc;
    docs.count_intersections =
        "How many times each ray crosses a surface in [tnear, tfar]: an int32 array of the "
        "rays' leading shape. Hits at one t on one mesh (a ray through a shared edge or "
        "vertex) count once.\n" +
        rays_doc;
    docs.list_intersections = R"doc(
Every crossing of every ray, sorted by t along each ray, counted as count_intersections counts
them. Returns a dict of flat arrays: ``ray_splits`` (number of rays + 1; ray i's crossings are
rows ray_splits[i]:ray_splits[i+1]), ``ray_ids``, ``geometry_ids``, ``primitive_ids``,
``primitive_uvs`` (K, 2), ``t_hit``, and ``entering`` (bool: the ray goes against the
triangle's normal, into the solid of an outward-wound closed mesh).
)doc" + rays_doc;
    docs.compute_occupancy =
        "1.0 where a point is inside the meshes, 0.0 outside (float32, the points' leading "
        "shape). Inside means an odd number of crossings along one fixed ray from the point, "
        "as in Open3D: meant for closed meshes, whatever their winding.\n"
        "nsamples: must be 1 (Open3D's vote over several rays is not offered).\n" +
        points_doc;
    bind_queries(
        scene,
        [](const RaycastingScene& self, const auto& query) {
            const auto snapshot = self.snapshot();
            return query(snapshot->view());
        },
        docs);
    scene.def(
        "compute_closest_points",
        [](const RaycastingScene& self, const py::handle& points_object, int nthreads) {
            const FloatInput points =
                float_input(points_object, "query_points", 3, "(..., 3)");
            const BatchConfig config = batch_config(nthreads);
            const auto snapshot = self.snapshot();
            return points.is_float32
                       ? closest_points_as<float>(snapshot->view(), points, config)
                       : closest_points_as<double>(snapshot->view(), points, config);
        },
        "query_points"_a, "nthreads"_a = 0,
        (R"doc(
The nearest point of the meshes to every query point (a BVH point query; ties in distance go
to the lower triangle). Returns a dict: ``points`` (..., 3), ``geometry_ids``,
``primitive_ids``, ``primitive_uvs`` (..., 2) and ``primitive_normals`` (..., 3). With no
triangles: NaN points and INVALID_ID.
)doc" + points_doc).c_str());
    scene.def(
        "compute_distance",
        [](const RaycastingScene& self, const py::handle& points, int nthreads) {
            return distances(self, points, nthreads, 1, false);
        },
        "query_points"_a, "nthreads"_a = 0,
        ("The unsigned distance from every point to the nearest triangle (the points' "
         "precision and leading shape; inf with no triangles).\n" +
         points_doc)
            .c_str());
    scene.def(
        "compute_signed_distance",
        [](const RaycastingScene& self, const py::handle& points, int nthreads, int nsamples) {
            return distances(self, points, nthreads, nsamples, true);
        },
        "query_points"_a, "nthreads"_a = 0, "nsamples"_a = 1,
        ("The distance to the nearest triangle, negative inside (inside as compute_occupancy "
         "decides it): meant for closed meshes.\nnsamples: must be 1.\n" +
         points_doc)
            .c_str());
    scene.def_static("create_rays_pinhole", &create_rays_pinhole, "fov_deg"_a, "center"_a,
                     "eye"_a, "up"_a, "width_px"_a, "height_px"_a, R"doc(
Rays of a pinhole camera at ``eye`` looking at ``center``: a float32 array of shape
(height_px, width_px, 6), rows from the top of the image, through the pixel centres, with
unit directions (so t_hit is the distance from the eye). fov_deg: the horizontal field of
view in degrees, as in Open3D.
)doc");
}

}  // namespace csgrt::python
