#pragma once

// NumPy arrays in and out of the batch queries (csg/batch.h): shape and dtype checks with
// messages that name the argument, views without copies for contiguous float32 and float64,
// and result arrays with the caller's leading shape.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "csgrt/csg/batch.h"

namespace csgrt::python {

namespace py = pybind11;

/// "(10, 5)": a shape as NumPy prints it.
std::string shape_text(const py::array& array);

/// An input array of floating-point vectors: shape (..., width), float32 or float64 kept as
/// they are (no copy when C-contiguous), any other real dtype converted once to float64.
/// Throws ValueError naming `what` for another shape or a non-numeric dtype.
struct FloatInput {
    py::array array;  ///< C-contiguous float32 or float64, shape (..., width)
    bool is_float32 = false;
    std::vector<py::ssize_t> leading;  ///< the shape without the last axis
    std::size_t count = 0;             ///< the product of `leading`

    template <class Real>
    const Real* data() const {
        return static_cast<const Real*>(array.data());
    }
};
FloatInput float_input(const py::handle& object, const char* what, py::ssize_t width,
                       const char* layout);

/// Memory for a result array of `bytes`, and its return when the array dies (with the GIL
/// held). Blocks of 1 MiB and more are kept for the next results rather than given back: a
/// fresh block is new pages, which the kernel zeroes as the batch's threads first write them,
/// and that was 14% of a loop of cast_rays on 10^6 rays (32 MB of results a call) on two
/// threads. At most 256 MiB is kept, the oldest given back first; smaller blocks come from and
/// go to malloc. The query writes every element of what it returns (misses too), so a kept
/// block's old contents never show.
void* result_memory(std::size_t bytes);
void release_result_memory(void* block, std::size_t bytes);
/// The bytes result_memory keeps for later results at the moment (for the tests).
std::size_t kept_result_memory();

/// A new array of `leading` + `trailing` shape, its elements unset (every query writes them
/// all), in result_memory.
template <class T>
py::array_t<T> output(const std::vector<py::ssize_t>& leading,
                      std::initializer_list<py::ssize_t> trailing = {}) {
    std::vector<py::ssize_t> shape = leading;
    shape.insert(shape.end(), trailing.begin(), trailing.end());
    std::size_t count = 1;
    for (const py::ssize_t extent : shape) count *= static_cast<std::size_t>(extent);
    const std::size_t bytes = std::max<std::size_t>(count * sizeof(T), 1);
    // The array's base owns the block: it goes back when the array and its views die.
    struct Block {
        void* data;
        std::size_t bytes;
        ~Block() { release_result_memory(data, bytes); }
    };
    std::unique_ptr<Block> block(new Block{result_memory(bytes), bytes});  // no temporary Block
    T* data = static_cast<T*>(block->data);
    py::capsule owner(block.get(), [](void* pointer) { delete static_cast<Block*>(pointer); });
    block.release();
    return py::array_t<T>(shape, data, owner);
}

template <class T>
std::span<T> span_of(py::array_t<T>& array) {
    return {array.mutable_data(), static_cast<std::size_t>(array.size())};
}

/// A dict of named results, in the order given.
inline py::dict named_results(std::initializer_list<std::pair<const char*, py::object>> results) {
    py::dict dict;
    for (const auto& [name, value] : results) dict[name] = value;
    return dict;
}

/// Rays of an (..., 6) input (origin, direction) with the interval [t_min, t_max].
template <class Real>
RayArrays<Real> ray_arrays(const FloatInput& rays, double t_min, double t_max) {
    RayArrays<Real> view;
    view.origins = strided_vectors(rays.data<Real>(), rays.count, 6);
    view.directions = strided_vectors(rays.data<Real>() + 3, rays.count, 6);
    view.default_t_min = t_min;
    view.default_t_max = t_max;
    return view;
}

template <class Real>
VectorArray<Real> point_arrays(const FloatInput& points) {
    return strided_vectors(points.data<Real>(), points.count, 3);
}

/// Checks a thread count argument (0: every core).
BatchConfig batch_config(int nthreads);

/// Checks an interval given to a ray query.
void check_interval(double tnear, double tfar);

/// The docstring fragments every query shares.
inline constexpr const char* kRaysDoc =
    "rays: array of shape (..., 6): origin x, y, z and direction x, y, z per ray, float32 or "
    "float64 (used in place when C-contiguous; other real dtypes are converted once to "
    "float64). Directions need not be unit length: t is in units of the direction's length.";
inline constexpr const char* kPointsDoc =
    "query_points: array of shape (..., 3), float32 or float64 (other real dtypes are converted "
    "once to float64).";
inline constexpr const char* kThreadsDoc =
    "nthreads: worker threads, 0 (default) for every core. Results do not depend on it.";

/// The end of every ray query's docstring: the rays, the interval, the threads.
inline std::string ray_query_doc() {
    return std::string(kRaysDoc) + "\ntnear, tfar: the interval of t searched (closed).\n" +
           kThreadsDoc;
}
/// The end of every point query's docstring: the points, the threads.
inline std::string point_query_doc() {
    return std::string(kPointsDoc) + "\n" + kThreadsDoc;
}

}  // namespace csgrt::python
