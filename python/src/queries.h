#pragma once

// The ray and point queries both Python scene classes share, written once over any target the
// batch functions take (a committed Scene, or a TriangleStructure). Each checks its inputs
// with the GIL held, allocates its result arrays, releases the GIL for the batch and returns.

#include <string>
#include <type_traits>
#include <unordered_set>

#include "arrays.h"

namespace csgrt::python {

/// The names cast_rays can return, in Open3D's order (and csgrt's shading normals).
inline const std::vector<std::string>& cast_ray_outputs() {
    static const std::vector<std::string> names{"t_hit", "geometry_ids", "primitive_ids",
                                                "primitive_uvs", "primitive_normals",
                                                "shading_normals"};
    return names;
}

/// The output only a csgrt.Scene's cast_rays gives: each hit's material index.
inline constexpr const char* kMaterialOutput = "material_ids";

/// Which outputs a call asked for: `requested` is None (Open3D's five) or names, from
/// cast_ray_outputs() and, `with_materials` (a Scene), kMaterialOutput.
std::unordered_set<std::string> requested_outputs(const py::object& requested,
                                                  bool with_materials);

/// The checked arguments of a ray query: the rays (float_input), the interval and the
/// threads, checked in that order.
struct RayQuery {
    FloatInput rays;
    double tnear = 0.0;
    double tfar = kInfinity;
    BatchConfig config;

    /// Calls run(ray arrays) on the rays in their own precision, without the GIL.
    template <class Run>
    void run_without_gil(Run&& run) const {
        py::gil_scoped_release release;
        if (rays.is_float32) {
            run(ray_arrays<float>(rays, tnear, tfar));
        } else {
            run(ray_arrays<double>(rays, tnear, tfar));
        }
    }
};
RayQuery ray_query(const py::handle& rays_object, double tnear, double tfar, int nthreads);

template <class Real, class Target>
py::dict cast_rays_as(const Target& target, const FloatInput& rays, double tnear, double tfar,
                      const std::unordered_set<std::string>& wanted, const BatchConfig& config) {
    const auto& leading = rays.leading;
    // Only the outputs asked for take memory (the others stay empty, never returned).
    const auto asked = [&](const char* name, auto type, std::initializer_list<py::ssize_t> tail) {
        using T = typename decltype(type)::type;
        return wanted.count(name) ? output<T>(leading, tail) : py::array_t<T>();
    };
    auto t = asked("t_hit", std::type_identity<Real>{}, {});
    auto geometry = asked("geometry_ids", std::type_identity<std::uint32_t>{}, {});
    auto primitive = asked("primitive_ids", std::type_identity<std::uint32_t>{}, {});
    auto uv = asked("primitive_uvs", std::type_identity<Real>{}, {2});
    auto normal = asked("primitive_normals", std::type_identity<Real>{}, {3});
    auto shading = asked("shading_normals", std::type_identity<Real>{}, {3});
    auto material = asked(kMaterialOutput, std::type_identity<std::uint32_t>{}, {});
    NearestHitOutputs<Real> outputs;
    if (wanted.count("t_hit")) outputs.t = span_of(t);
    if (wanted.count("geometry_ids")) outputs.object_id = span_of(geometry);
    if (wanted.count("primitive_ids")) outputs.primitive_id = span_of(primitive);
    if (wanted.count("primitive_uvs")) outputs.uv = span_of(uv);
    if (wanted.count("primitive_normals")) outputs.geometric_normal = span_of(normal);
    if (wanted.count("shading_normals")) outputs.shading_normal = span_of(shading);
    if (wanted.count(kMaterialOutput)) outputs.material = span_of(material);
    {
        py::gil_scoped_release release;
        intersect(target, ray_arrays<Real>(rays, tnear, tfar), outputs, config);
    }
    py::dict result;
    if (wanted.count("t_hit")) result["t_hit"] = t;
    if (wanted.count("geometry_ids")) result["geometry_ids"] = geometry;
    if (wanted.count("primitive_ids")) result["primitive_ids"] = primitive;
    if (wanted.count("primitive_uvs")) result["primitive_uvs"] = uv;
    if (wanted.count("primitive_normals")) result["primitive_normals"] = normal;
    if (wanted.count("shading_normals")) result["shading_normals"] = shading;
    if (wanted.count(kMaterialOutput)) result[kMaterialOutput] = material;
    return result;
}

template <class Target>
py::dict cast_rays(const Target& target, const py::handle& rays_object, double tnear,
                   double tfar, const py::object& requested, int nthreads) {
    const FloatInput rays = float_input(rays_object, "rays", 6, "(..., 6)");
    check_interval(tnear, tfar);
    const auto wanted = requested_outputs(requested, std::is_same_v<Target, Scene>);
    const BatchConfig config = batch_config(nthreads);
    return rays.is_float32 ? cast_rays_as<float>(target, rays, tnear, tfar, wanted, config)
                           : cast_rays_as<double>(target, rays, tnear, tfar, wanted, config);
}

template <class Target>
py::array_t<bool> test_occlusions(const Target& target, const py::handle& rays_object,
                                  double tnear, double tfar, int nthreads) {
    const RayQuery query = ray_query(rays_object, tnear, tfar, nthreads);
    auto result = output<bool>(query.rays.leading);
    // NumPy's bool is one byte holding 0 or 1: the batch's uint8 answers, in place.
    const std::span<std::uint8_t> out(reinterpret_cast<std::uint8_t*>(result.mutable_data()),
                                      query.rays.count);
    query.run_without_gil([&](const auto& view) { occluded(target, view, out, query.config); });
    return result;
}

template <class Target>
py::array_t<std::int32_t> count_intersections(const Target& target,
                                              const py::handle& rays_object, double tnear,
                                              double tfar, int nthreads) {
    const RayQuery query = ray_query(rays_object, tnear, tfar, nthreads);
    auto result = output<std::int32_t>(query.rays.leading);  // Open3D's dtype
    // Counts are far below 2^31; signed and unsigned variants of one type may alias.
    const std::span<std::uint32_t> out(reinterpret_cast<std::uint32_t*>(result.mutable_data()),
                                       query.rays.count);
    query.run_without_gil(
        [&](const auto& view) { count_crossings(target, view, out, query.config); });
    return result;
}

template <class Real, class Target>
py::dict list_intersections_as(const Target& target, const FloatInput& rays, double tnear,
                               double tfar, const BatchConfig& config) {
    const RayArrays<Real> view = ray_arrays<Real>(rays, tnear, tfar);
    std::vector<std::uint32_t> counts(rays.count);
    py::array_t<std::uint64_t> splits(static_cast<py::ssize_t>(rays.count + 1));
    {
        py::gil_scoped_release release;
        count_crossings(target, view, std::span<std::uint32_t>(counts), config);
        crossing_offsets(counts, span_of(splits));
    }
    const auto total = static_cast<py::ssize_t>(splits.at(rays.count));
    py::array_t<std::uint32_t> ray_ids(total), geometry(total), primitive(total);
    py::array_t<Real> t(total), uv(std::vector<py::ssize_t>{total, 2});
    py::array_t<bool> entering(total);
    {
        py::gil_scoped_release release;
        auto ids = span_of(ray_ids);
        const std::uint64_t* offsets = splits.data();
        for (std::size_t i = 0; i < rays.count; ++i) {
            for (std::uint64_t k = offsets[i]; k < offsets[i + 1]; ++k) {
                ids[k] = static_cast<std::uint32_t>(i);
            }
        }
        CrossingOutputs<Real> outputs;
        outputs.offsets = {offsets, rays.count + 1};
        outputs.t = span_of(t);
        outputs.object_id = span_of(geometry);
        outputs.primitive_id = span_of(primitive);
        outputs.uv = span_of(uv);
        outputs.entering = {reinterpret_cast<std::uint8_t*>(entering.mutable_data()),
                            static_cast<std::size_t>(total)};
        list_crossings(target, view, outputs, config);
    }
    return named_results({{"ray_splits", splits},
                          {"ray_ids", ray_ids},
                          {"geometry_ids", geometry},
                          {"primitive_ids", primitive},
                          {"primitive_uvs", uv},
                          {"t_hit", t},
                          {"entering", entering}});
}

template <class Target>
py::dict list_intersections(const Target& target, const py::handle& rays_object, double tnear,
                            double tfar, int nthreads) {
    const RayQuery query = ray_query(rays_object, tnear, tfar, nthreads);
    return query.rays.is_float32
               ? list_intersections_as<float>(target, query.rays, tnear, tfar, query.config)
               : list_intersections_as<double>(target, query.rays, tnear, tfar, query.config);
}

void check_samples(int nsamples);

template <class Target>
py::array_t<float> compute_occupancy(const Target& target, const py::handle& points_object,
                                     int nthreads, int nsamples) {
    const FloatInput points = float_input(points_object, "query_points", 3, "(..., 3)");
    check_samples(nsamples);
    const BatchConfig config = batch_config(nthreads);
    std::vector<std::uint8_t> inside(points.count);
    auto result = output<float>(points.leading);  // Open3D's dtype: 0.0 or 1.0
    auto out = span_of(result);
    py::gil_scoped_release release;
    if (points.is_float32) {
        contains(target, point_arrays<float>(points), std::span<std::uint8_t>(inside), config);
    } else {
        contains(target, point_arrays<double>(points), std::span<std::uint8_t>(inside), config);
    }
    for (std::size_t i = 0; i < points.count; ++i) out[i] = inside[i] ? 1.0f : 0.0f;
    return result;
}

/// The docstrings of the queries both scene classes bind (bind_queries): each says what its
/// targets are.
struct QueryDocs {
    std::string cast_rays;
    std::string test_occlusions;
    std::string count_intersections;
    std::string list_intersections;
    std::string compute_occupancy;
};

/// Binds cast_rays, test_occlusions, count_intersections, list_intersections and
/// compute_occupancy on `cls` with the same arguments and defaults in both scene classes, each
/// answered on the target `with_target(self, query)` hands to `query` (a RaycastingScene's
/// snapshot, a Scene's committed scene), which it keeps alive for the query.
template <class Class, class WithTarget>
void bind_queries(Class& cls, WithTarget with_target, const QueryDocs& docs) {
    using namespace pybind11::literals;
    using Self = typename Class::type;
    cls.def(
        "cast_rays",
        [with_target](const Self& self, const py::handle& rays, double tnear, double tfar,
                      const py::object& outputs, int nthreads) {
            return with_target(self, [&](const auto& target) {
                return cast_rays(target, rays, tnear, tfar, outputs, nthreads);
            });
        },
        "rays"_a, "tnear"_a = 0.0, "tfar"_a = kInfinity, "outputs"_a = py::none(), "nthreads"_a = 0,
        docs.cast_rays.c_str());
    // The three queries of (rays, tnear, tfar, nthreads), each a generic call of its function.
    const auto def_ray_query = [&](const char* name, auto query, const std::string& doc) {
        cls.def(
            name,
            [with_target, query](const Self& self, const py::handle& rays, double tnear,
                                 double tfar, int nthreads) {
                return with_target(self, [&](const auto& target) {
                    return query(target, rays, tnear, tfar, nthreads);
                });
            },
            "rays"_a, "tnear"_a = 0.0, "tfar"_a = kInfinity, "nthreads"_a = 0, doc.c_str());
    };
    def_ray_query(
        "test_occlusions",
        [](const auto& target, const auto&... rest) { return test_occlusions(target, rest...); },
        docs.test_occlusions);
    def_ray_query(
        "count_intersections",
        [](const auto& target, const auto&... rest) {
            return count_intersections(target, rest...);
        },
        docs.count_intersections);
    def_ray_query(
        "list_intersections",
        [](const auto& target, const auto&... rest) { return list_intersections(target, rest...); },
        docs.list_intersections);
    cls.def(
        "compute_occupancy",
        [with_target](const Self& self, const py::handle& points, int nthreads, int nsamples) {
            return with_target(self, [&](const auto& target) {
                return compute_occupancy(target, points, nthreads, nsamples);
            });
        },
        "query_points"_a, "nthreads"_a = 0, "nsamples"_a = 1, docs.compute_occupancy.c_str());
}

}  // namespace csgrt::python
