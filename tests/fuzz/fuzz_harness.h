#pragma once

#include <unistd.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "csgrt/mesh/mesh.h"
#include "csgrt/mesh/mesh_io.h"
#include "csgrt/core/error.h"
#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/render/renderer.h"

namespace csgrt::fuzz {

/// Rays from the corners of a box around `bounds` through its centre, and along the axes from
/// outside: a handful of queries that visit what a loaded input built.
template <class Query>
void shoot_rays(const Aabb& bounds, Query&& query) {
    const bool finite = is_finite(bounds.lower) && is_finite(bounds.upper) &&
                        (bounds.lower.array() <= bounds.upper.array()).all();
    const Point3 lower = finite ? bounds.lower : Point3(-1, -1, -1);
    const Point3 upper = finite ? bounds.upper : Point3(1, 1, 1);
    const Point3 centre = 0.5 * (lower + upper);
    for (int corner = 0; corner < 8; ++corner) {
        const Point3 from((corner & 1) ? upper.x() : lower.x(),
                          (corner & 2) ? upper.y() : lower.y(),
                          (corner & 4) ? upper.z() : lower.z());
        const Point3 origin = centre + 2.0 * (from - centre);
        query(Ray{origin, centre - origin});
    }
    for (int axis = 0; axis < 3; ++axis) {
        Point3 origin = centre;
        origin[axis] = lower[axis] - (upper[axis] - lower[axis]) - 1.0;
        Vector3 direction = Vector3::Zero();
        direction[axis] = 1.0;
        query(Ray{origin, direction});
    }
}

/// The scene fuzz target's body: parses `text` as a scene file (mesh paths relative to
/// `directory`); a SceneError is the expected answer to bad input, anything else escaping is a
/// defect. A scene that loads is counted as `csgrt info` counts it, committed, queried and
/// rendered at 4x3 pixels on one thread (what `csgrt render` does, so a scene that loads but
/// hangs or blows up the renderer is found). Returns whether it loaded.
inline bool run_scene(std::string_view text, const std::filesystem::path& directory) {
    std::optional<Scene> scene;
    try {
        scene.emplace(load_scene_from_string(text, "fuzz.json", directory));
    } catch (const SceneError&) {
        return false;
    }
    try {
        scene->commit();
    } catch (const InvalidParameter&) {
        return true;  // an unusable camera is reported by commit, as documented
    }
    (void)count_scene_shapes(*scene);
    QueryScratch scratch;
    shoot_rays(scene->bounds(), [&](const Ray& ray) {
        (void)scene->intersect(ray, scratch);
        (void)scene->occluded(ray, scratch);
    });
    RenderSettings settings;
    settings.width = 4;
    settings.height = 3;
    settings.threads = 1;
    (void)render(*scene, settings);
    return true;
}

/// A file of this process for the mesh fuzz targets: load_mesh reads files, and chooses the
/// reader by extension.
inline std::filesystem::path scratch_file(std::string_view extension) {
    return std::filesystem::temp_directory_path() /
           ("csgrt_fuzz_" + std::to_string(::getpid()) + "." + std::string(extension));
}

/// The mesh fuzz targets' body: `bytes` as a file with `extension` ("off", "obj", "ply",
/// "stl"); MeshError is the expected answer to bad input. A mesh that loads is built (float
/// and double) and queried, spans and membership included. Returns whether it loaded.
inline bool run_mesh(std::span<const std::uint8_t> bytes, std::string_view extension) {
    const std::filesystem::path path = scratch_file(extension);
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(bytes.data()),
                  static_cast<std::streamsize>(bytes.size()));
    }
    TriangleMeshData data;
    try {
        data = load_mesh(path);
    } catch (const MeshError&) {
        return false;
    }
    for (const bool double_precision : {false, true}) {
        MeshConfig config;
        config.double_precision = double_precision;
        const Mesh mesh(data, config);
        shoot_rays(mesh.bounds(), [&](const Ray& ray) {
            (void)mesh.intersect(ray);
            (void)mesh.occluded(ray);
            (void)mesh.spans(ray);
            (void)mesh.contains(ray.origin);
        });
    }
    return true;
}

}  // namespace csgrt::fuzz
