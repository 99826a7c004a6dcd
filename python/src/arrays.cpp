#include "arrays.h"
#include "queries.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <new>

#include "csgrt/core/error.h"
#include "csgrt/core/huge_pages.h"

namespace csgrt::python {

namespace {

constexpr std::size_t kSmallestKept = std::size_t(1) << 20;
constexpr std::size_t kMostKept = std::size_t(256) << 20;

/// The kept blocks, oldest first, by their size (a multiple of 2 MiB).
struct KeptBlocks {
    std::mutex mutex;
    std::deque<std::pair<std::size_t, void*>> blocks;
    std::size_t bytes = 0;
};

/// Never destroyed: arrays may die during the interpreter's shutdown, after static objects.
KeptBlocks& kept_blocks() {
    static KeptBlocks* kept = new KeptBlocks;
    return *kept;
}

}  // namespace

void* result_memory(std::size_t bytes) {
    if (bytes < kSmallestKept) {
        void* block = std::malloc(bytes);
        if (block == nullptr) throw std::bad_alloc();
        return block;
    }
    const std::size_t size = huge_page_block_size(bytes);
    {
        KeptBlocks& kept = kept_blocks();
        const std::lock_guard<std::mutex> lock(kept.mutex);
        // The newest block of the size: the likeliest still in cache.
        for (auto it = kept.blocks.rbegin(); it != kept.blocks.rend(); ++it) {
            if (it->first != size) continue;
            void* block = it->second;
            kept.bytes -= size;
            kept.blocks.erase(std::next(it).base());
            return block;
        }
    }
    return allocate_huge_page_block(size);
}

void release_result_memory(void* block, std::size_t bytes) {
    if (bytes < kSmallestKept) {
        std::free(block);
        return;
    }
    const std::size_t size = huge_page_block_size(bytes);
    KeptBlocks& kept = kept_blocks();
    const std::lock_guard<std::mutex> lock(kept.mutex);
    kept.blocks.emplace_back(size, block);
    kept.bytes += size;
    while (kept.bytes > kMostKept) {
        free_huge_page_block(kept.blocks.front().second);
        kept.bytes -= kept.blocks.front().first;
        kept.blocks.pop_front();
    }
}

std::size_t kept_result_memory() {
    KeptBlocks& kept = kept_blocks();
    const std::lock_guard<std::mutex> lock(kept.mutex);
    return kept.bytes;
}

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
