// csgrt_batch_timer: the C++ batch query (csg/batch.h) on the rays and the mesh that
// bench/python/bench_python.py casts from Python, so that the script measures the Python
// module's overhead as a ratio of two figures from one run on the very same rays.
//
//   csgrt_batch_timer VERTICES TRIANGLES RAYS [--repetitions 5] [--threads 1,2]
//
// VERTICES: float32 (N, 3), TRIANGLES: uint32 (M, 3), RAYS: float32 (R, 6), each a raw
// little-endian file (numpy's tofile). The mesh is built as RaycastingScene.add_triangles
// builds it (a TriangleSet<float> under the factory's "bvh", one geometry), and the outputs are
// cast_rays' for the same `outputs` argument, into arrays allocated once. Prints one JSON list
// of rows {variant, threads, seconds, min, max, cpu_seconds}: the median, fastest and slowest
// wall time of the repetitions after one warm-up, and the median process CPU time.

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "csgrt/accel/factory.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/csg/batch.h"

namespace {

template <class T>
std::vector<T> read_raw(const std::string& path, std::size_t columns) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw std::runtime_error(path + ": cannot be read");
    const auto bytes = static_cast<std::size_t>(in.tellg());
    if (bytes % (columns * sizeof(T)) != 0) {
        throw std::runtime_error(path + ": " + std::to_string(bytes) +
                                 " bytes is not a whole number of rows of " +
                                 std::to_string(columns) + " values");
    }
    std::vector<T> values(bytes / sizeof(T));
    in.seekg(0);
    in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(bytes));
    return values;
}

double process_cpu_seconds() {
    timespec now{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return double(now.tv_sec) + 1e-9 * double(now.tv_nsec);
}

struct Timing {
    double median = 0, fastest = 0, slowest = 0, cpu = 0;
};

template <class Run>
Timing time_runs(int repetitions, const Run& run) {
    run();  // warm-up, as bench_python.py's best_of
    std::vector<double> wall, cpu;
    for (int k = 0; k < repetitions; ++k) {
        const auto start = std::chrono::steady_clock::now();
        const double start_cpu = process_cpu_seconds();
        run();
        wall.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        cpu.push_back(process_cpu_seconds() - start_cpu);
    }
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    };
    return {median(wall), *std::min_element(wall.begin(), wall.end()),
            *std::max_element(wall.begin(), wall.end()), median(cpu)};
}

}  // namespace

int main(int argc, char** argv) try {
    using namespace csgrt;
    if (argc < 4) {
        std::cerr << "usage: csgrt_batch_timer VERTICES TRIANGLES RAYS [--repetitions N] "
                     "[--threads 1,2]\n";
        return 2;
    }
    int repetitions = 5;
    std::vector<int> thread_counts{1, 2};
    for (int i = 4; i + 1 < argc; i += 2) {
        const std::string option = argv[i];
        if (option == "--repetitions") {
            repetitions = std::max(1, std::stoi(argv[i + 1]));
        } else if (option == "--threads") {
            thread_counts.clear();
            std::stringstream list(argv[i + 1]);
            for (std::string item; std::getline(list, item, ',');)
                thread_counts.push_back(std::stoi(item));
        } else {
            throw std::runtime_error("unknown option " + option);
        }
    }
    const auto corners = read_raw<float>(argv[1], 3);
    const auto indices = read_raw<std::uint32_t>(argv[2], 3);
    const auto rays = read_raw<float>(argv[3], 6);

    std::vector<Eigen::Vector3d> vertices(corners.size() / 3);
    for (std::size_t i = 0; i < vertices.size(); ++i)
        vertices[i] = Eigen::Vector3d(corners[3 * i], corners[3 * i + 1], corners[3 * i + 2]);
    std::vector<std::array<std::uint32_t, 3>> triangles(indices.size() / 3);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        triangles[t] = {indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]};
        for (std::uint32_t index : triangles[t]) {
            if (index >= vertices.size()) throw std::runtime_error("a triangle index is too large");
        }
    }
    const TriangleSet<float> set(vertices, triangles);
    const auto structure = make_accelerator("bvh", set);
    const std::vector<std::uint32_t> object_of_triangle(triangles.size(), 0);
    const std::vector<std::uint32_t> first_triangle{0};
    TriangleStructure<float> mesh;
    mesh.triangles = &set;
    mesh.structure = structure.get();
    mesh.object_of_triangle = object_of_triangle;
    mesh.first_triangle = first_triangle;

    const std::size_t n = rays.size() / 6;
    RayArrays<float> ray_arrays;
    ray_arrays.origins = strided_vectors(rays.data(), n, 6);
    ray_arrays.directions = strided_vectors(rays.data() + 3, n, 6);

    std::vector<float> t(n), uv(2 * n), normal(3 * n);
    std::vector<std::uint32_t> geometry(n), primitive(n);
    NearestHitOutputs<float> all;
    all.t = t;
    all.object_id = geometry;
    all.primitive_id = primitive;
    all.uv = uv;
    all.geometric_normal = normal;
    NearestHitOutputs<float> t_and_id;
    t_and_id.t = t;
    t_and_id.primitive_id = primitive;

    std::string rows;
    for (int threads : thread_counts) {
        BatchConfig config;
        config.threads = threads;
        for (const auto& [outputs, label] :
             {std::pair{&all, "C++ batch intersect (all outputs)"},
              std::pair{&t_and_id, "C++ batch intersect (t, id)"}}) {
            const Timing timing =
                time_runs(repetitions, [&] { intersect(mesh, ray_arrays, *outputs, config); });
            char row[256];
            std::snprintf(row, sizeof row,
                          "%s{\"variant\": \"%s\", \"threads\": %d, \"seconds\": %.9g, "
                          "\"min\": %.9g, \"max\": %.9g, \"cpu_seconds\": %.9g}",
                          rows.empty() ? "" : ", ", label, threads, timing.median,
                          timing.fastest, timing.slowest, timing.cpu);
            rows += row;
        }
    }
    std::cout << "[" << rows << "]\n";
    return 0;
} catch (const std::exception& error) {
    std::cerr << "csgrt_batch_timer: " << error.what() << "\n";
    return 1;
}
