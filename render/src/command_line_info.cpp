#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>
#include <string>
#include <unordered_set>
#include <variant>
#include <vector>

#include "command_line_internal.h"
#include "csgrt/mesh/mesh.h"

namespace csgrt::command_line {

namespace {

/// {"x": .., "y": .., "z": ..} of a point or vector, for --json. (Its text is dumped with
/// invalid UTF-8 replaced, so a file name in any encoding prints.)
nlohmann::json json_of(const Vector3& v) {
    return {{"x", v.x()}, {"y", v.y()}, {"z", v.z()}};
}

std::string describe(const Vector3& v) {
    std::ostringstream text;
    text.precision(6);
    text << '(' << v.x() << ", " << v.y() << ", " << v.z() << ')';
    return text.str();
}

/// A distinct mesh of the scene and the first top-level object it is under.
struct SceneMesh {
    const Mesh* mesh;
    std::size_t object;
};

/// Every distinct Mesh in the trees under the scene's objects, in the order the objects list
/// them; each shape is visited once, however often the trees share it.
std::vector<SceneMesh> distinct_meshes(const Scene& scene) {
    std::vector<SceneMesh> meshes;
    std::unordered_set<const Shape*> seen;
    std::vector<const Shape*> stack;
    for (std::size_t i = 0; i < scene.objects().size(); ++i) {
        stack.push_back(scene.objects()[i].shape.get());
        while (!stack.empty()) {
            const Shape* shape = stack.back();
            stack.pop_back();
            if (!seen.insert(shape).second) continue;
            if (const auto* mesh = dynamic_cast<const Mesh*>(shape)) meshes.push_back({mesh, i});
            for (const Shape* child : shape->children()) stack.push_back(child);
        }
    }
    return meshes;
}

/// The object's name in quotes, or its index when it has none.
std::string object_label(const Scene& scene, std::size_t object) {
    const std::string& name = scene.objects()[object].name;
    return name.empty() ? "object " + std::to_string(object) : '"' + name + '"';
}

/// The text report lists at most this many meshes one per line (a scene may hold many).
constexpr std::size_t kMeshLines = 100;

/// `csgrt info --json`: what the text report says, as one JSON object (docs/rendering.md).
void print_info_json(const std::string& scene_path, const Scene& scene,
                     const std::map<std::string, std::uint64_t>& counts, std::uint64_t shapes,
                     std::size_t unbounded, std::uint64_t triangles, std::ostream& out) {
    std::size_t point_lights = 0;
    for (const Light& light : scene.lights())
        point_lights += std::holds_alternative<PointLight>(light);
    const Camera& camera = scene.camera();
    const bool pinhole = camera.projection == Camera::Projection::Pinhole;
    nlohmann::json camera_json = {{"projection", pinhole ? "pinhole" : "orthographic"},
                                  {"position", json_of(camera.position)},
                                  {"look_at", json_of(camera.look_at)}};
    if (pinhole) {
        camera_json["vertical_fov_degrees"] = camera.vertical_fov_degrees;
    } else {
        camera_json["orthographic_height"] = camera.orthographic_height;
    }
    nlohmann::json meshes = nlohmann::json::array();
    for (const SceneMesh& entry : distinct_meshes(scene)) {
        const MeshReport& report = entry.mesh->report();
        meshes.push_back({{"object", entry.object},
                          {"object_name", scene.objects()[entry.object].name},
                          {"format", report.format},
                          {"vertices", report.vertices},
                          {"triangles", report.triangles},
                          {"closed", report.is_closed},
                          {"boundary_edges", report.boundary_edges},
                          {"non_manifold_edges", report.non_manifold_edges},
                          {"orientable", report.orientable},
                          {"volume", report.volume},
                          {"welded_vertices", report.welded_vertices},
                          {"file_normals", report.file_normals}});
    }
    const Aabb& bounds = scene.bounds();
    const nlohmann::json info = {
        {"scene", scene_path},
        {"objects",
         {{"top_level", scene.objects().size()}, {"unbounded", unbounded}, {"shapes", shapes}}},
        {"kinds", counts},
        {"triangles", triangles},
        {"meshes", meshes},
        {"materials", scene.materials().size()},
        {"lights",
         {{"total", scene.lights().size()},
          {"point", point_lights},
          {"directional", scene.lights().size() - point_lights}}},
        {"camera", camera_json},
        {"bounds", bounds.is_empty() ? nlohmann::json(nullptr)
                                     : nlohmann::json{{"lower", json_of(bounds.lower)},
                                                      {"upper", json_of(bounds.upper)}}},
        {"structure",
         {{"name", scene.accelerator_name()}, {"reason", scene.accelerator_reason()}}}};
    out << info.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
}

}  // namespace

void info_command(const std::string& scene_path, bool json, CommandLineStreams streams) {
    Scene scene = load_checked(scene_path);
    scene.commit();  // "auto": what a render without --accel would build
    // Memoised per distinct shape: a 2^64-leaf expansion costs what was loaded, not 2^64.
    const SceneShapeCounts counts = count_scene_shapes(scene);
    std::size_t unbounded = 0;
    for (const SceneObject& object : scene.objects()) {
        if (!object.shape->bounds().is_finite()) ++unbounded;
    }
    if (json) {
        print_info_json(scene_path, scene, counts.by_kind, counts.shapes, unbounded,
                        counts.triangles, streams.out);
        return;
    }
    std::ostream& out = streams.out;
    out << "scene:      " << scene_path << '\n';
    out << "objects:    " << scene.objects().size() << " top-level (" << unbounded
        << " unbounded), " << counts.shapes << " shapes in the trees under them (" << counts.leaves
        << " leaves):\n";
    for (const auto& [kind, count] : counts.by_kind) {
        char row[96];
        std::snprintf(row, sizeof(row), "  %-18s %llu", kind.c_str(),
                      static_cast<unsigned long long>(count));
        out << row;
        if (kind == "mesh") out << " (" << counts.triangles << " triangles in all)";
        out << '\n';
    }
    if (const auto meshes = counts.by_kind.find("mesh"); meshes != counts.by_kind.end()) {
        out << "meshes:     " << counts.closed_meshes
            << " closed (solids: CSG operands, inside/outside), "
            << meshes->second - counts.closed_meshes << " open\n";
        // Each distinct mesh, with what loading found: closed or why not (docs/meshes.md).
        const std::vector<SceneMesh> distinct = distinct_meshes(scene);
        for (std::size_t k = 0; k < distinct.size() && k < kMeshLines; ++k) {
            out << "  " << object_label(scene, distinct[k].object) << ": "
                << csgrt::describe(distinct[k].mesh->report()) << '\n';
        }
        if (distinct.size() > kMeshLines)
            out << "  ... and " << distinct.size() - kMeshLines << " more meshes\n";
    }
    std::size_t point_lights = 0;
    for (const Light& light : scene.lights())
        point_lights += std::holds_alternative<PointLight>(light);
    out << "materials:  " << scene.materials().size() << " (including \"default\")\n";
    out << "lights:     " << scene.lights().size() << " (" << point_lights << " point, "
        << scene.lights().size() - point_lights << " directional)"
        << (scene.lights().empty() ? "; rendered with an eye light" : "") << '\n';
    const Camera& camera = scene.camera();
    out << "camera:     "
        << (camera.projection == Camera::Projection::Pinhole ? "pinhole" : "orthographic") << " at "
        << describe(camera.position) << " looking at " << describe(camera.look_at);
    if (camera.projection == Camera::Projection::Pinhole) {
        out << ", " << camera.vertical_fov_degrees << " degrees vertical field of view\n";
    } else {
        out << ", " << camera.orthographic_height << " units high\n";
    }
    const Aabb& bounds = scene.bounds();
    if (bounds.is_empty()) {
        out << "bounds:     none (no bounded objects)\n";
    } else {
        out << "bounds:     " << describe(bounds.lower) << " to " << describe(bounds.upper) << '\n';
    }
    out << "structure:  " << scene.accelerator_name() << " (auto: " << scene.accelerator_reason()
        << ")\n";
}

void validate_command(const std::string& scene_path) {
    Scene scene = load_checked(scene_path);
    scene.commit();
}

}  // namespace csgrt::command_line
