#include "arrays.h"
#include "queries.h"

#include <algorithm>
#include <cmath>

#include "csgrt/core/error.h"

namespace csgrt::python {

std::string shape_text(const py::array& array) {
    std::string text = "(";
    for (py::ssize_t axis = 0; axis < array.ndim(); ++axis) {
        if (axis > 0) text += ", ";
        text += std::to_string(array.shape(axis));
    }
    if (array.ndim() == 1) text += ",";
    return text + ")";
}

FloatInput float_input(const py::handle& object, const char* what, py::ssize_t width,
                       const char* layout) {
    py::array array;
    try {
        array = py::array::ensure(object);
    } catch (const py::error_already_set&) {
    }
    if (!array) {
        throw py::value_error(std::string(what) + ": expected a NumPy array (or something "
                              "convertible to one), got " +
                              std::string(py::str(py::type::of(object).attr("__name__"))));
    }
    const char kind = array.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b') {
        throw py::value_error(std::string(what) + ": expected a float32 or float64 array, got "
                              "dtype " + std::string(py::str(array.dtype())));
    }
    if (array.ndim() < 1 || array.shape(array.ndim() - 1) != width) {
        throw py::value_error(std::string(what) + ": expected an array of shape " + layout +
                              ", got " + shape_text(array));
    }
    FloatInput input;
    if (array.dtype().is(py::dtype::of<float>())) {
        input.is_float32 = true;
        input.array = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
    } else {
        // float64 stays as it is; integers, booleans and float16 become float64 once.
        input.array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
    }
    input.count = 1;
    for (py::ssize_t axis = 0; axis + 1 < array.ndim(); ++axis) {
        input.leading.push_back(array.shape(axis));
        input.count *= static_cast<std::size_t>(array.shape(axis));
    }
    return input;
}

BatchConfig batch_config(int nthreads) {
    if (nthreads < 0) {
        throw py::value_error("nthreads: expected 0 (every core) or a positive count, got " +
                              std::to_string(nthreads));
    }
    BatchConfig config;
    config.threads = nthreads;
    return config;
}

void check_interval(double tnear, double tfar) {
    if (std::isnan(tnear) || std::isnan(tfar) || tnear > tfar) {
        throw py::value_error("tnear, tfar: expected tnear <= tfar, got " + std::to_string(tnear) +
                              " and " + std::to_string(tfar));
    }
}

std::unordered_set<std::string> requested_outputs(const py::object& requested,
                                                  bool with_materials) {
    std::vector<std::string> known = cast_ray_outputs();
    if (requested.is_none()) return {known.begin(), known.begin() + 5};
    if (with_materials) known.emplace_back(kMaterialOutput);
    std::unordered_set<std::string> wanted;
    if (py::isinstance<py::str>(requested)) {
        throw py::value_error("outputs: expected a list of names, got the string '" +
                              requested.cast<std::string>() + "'");
    }
    for (const py::handle& item : requested) {
        const std::string name = py::str(item);
        if (std::find(known.begin(), known.end(), name) == known.end()) {
            std::string list;
            for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
            throw py::value_error("outputs: unknown output '" + name + "'; known: " + list);
        }
        wanted.insert(name);
    }
    return wanted;
}

RayQuery ray_query(const py::handle& rays_object, double tnear, double tfar, int nthreads) {
    RayQuery query;
    query.rays = float_input(rays_object, "rays", 6, "(..., 6)");
    check_interval(tnear, tfar);
    query.tnear = tnear;
    query.tfar = tfar;
    query.config = batch_config(nthreads);
    return query;
}

void check_samples(int nsamples) {
    if (nsamples != 1) {
        throw py::value_error("nsamples: csgrt decides inside/outside with one ray (the "
                              "crossing parity); expected 1, got " + std::to_string(nsamples));
    }
}

}  // namespace csgrt::python
