#include "csgrt/render/cost_layers.h"

#include <chrono>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "csgrt/core/instance.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/painted.h"
#include "csgrt/mesh/mesh.h"

namespace csgrt {

namespace {

using ShapePointer = std::shared_ptr<const Shape>;

/// The children of `shape` as shared pointers. A compound hands out references only, so its
/// children are aliasing pointers that keep the compound (and so the child) alive.
std::vector<ShapePointer> shared_children(const ShapePointer& shape) {
    if (const auto* instance = dynamic_cast<const Instance*>(shape.get())) {
        return {instance->shared_shape()};
    }
    if (const auto* boolean = dynamic_cast<const Boolean*>(shape.get())) {
        return {boolean->shared_first(), boolean->shared_second()};
    }
    if (const auto* painted = dynamic_cast<const Painted*>(shape.get())) {
        return {painted->shared_shape()};
    }
    if (const auto* compound = dynamic_cast<const Compound*>(shape.get())) {
        std::vector<ShapePointer> children;
        children.reserve(compound->size());
        for (std::size_t i = 0; i < compound->size(); ++i) {
            children.emplace_back(shape, &compound->child(i));
        }
        return children;
    }
    return {};
}

/// `mesh` built again from its stored triangles, with `structure` over them.
ShapePointer rebuilt_mesh(const Mesh& mesh, std::string_view structure) {
    TriangleMeshData data;
    data.triangles.reserve(mesh.triangle_count());
    for (std::size_t i = 0; i < mesh.triangle_count(); ++i) {
        const std::array<std::uint32_t, 3>& triangle = mesh.triangle(i);
        for (int k = 0; k < 3; ++k) {
            if (triangle[k] >= data.vertices.size()) data.vertices.resize(triangle[k] + 1);
            data.vertices[triangle[k]] = mesh.corner(i, k);
        }
        data.triangles.push_back(triangle);
    }
    MeshConfig config;
    config.double_precision = mesh.double_precision();
    config.accelerator = std::string(structure);
    return std::make_shared<Mesh>(std::move(data), config);
}

/// Rebuilds trees bottom-up, each distinct shape once.
class Rebuilder {
public:
    explicit Rebuilder(std::string_view structure) : structure_(structure) {}

    ShapePointer operator()(const ShapePointer& root) {
        // An explicit stack: a scene file may chain 100,000 instances.
        std::vector<std::pair<ShapePointer, bool>> stack = {{root, false}};
        while (!stack.empty()) {
            const auto [shape, expanded] = stack.back();
            if (done_.count(shape.get()) != 0) {
                stack.pop_back();
                continue;
            }
            const std::vector<ShapePointer> children = shared_children(shape);
            if (!expanded) {
                stack.back().second = true;
                for (const ShapePointer& child : children) {
                    if (done_.count(child.get()) == 0) stack.emplace_back(child, false);
                }
                continue;
            }
            stack.pop_back();
            done_[shape.get()] = rebuilt(shape, children);
        }
        return done_.at(root.get());
    }

private:
    ShapePointer rebuilt(const ShapePointer& shape, const std::vector<ShapePointer>& children) {
        if (const auto* mesh = dynamic_cast<const Mesh*>(shape.get())) {
            return rebuilt_mesh(*mesh, structure_);
        }
        std::vector<ShapePointer> parts;
        bool same = true;
        for (const ShapePointer& child : children) {
            parts.push_back(done_.at(child.get()));
            same = same && parts.back().get() == child.get();
        }
        if (dynamic_cast<const Compound*>(shape.get()) != nullptr) {
            CompoundConfig config;
            config.accelerator = std::string(structure_);
            return std::make_shared<Compound>(std::move(parts), config);
        }
        // Nothing below changed: no structure in this subtree.
        if (same) return shape;
        if (const auto* instance = dynamic_cast<const Instance*>(shape.get())) {
            return std::make_shared<Instance>(parts[0], instance->world_from_object());
        }
        if (const auto* boolean = dynamic_cast<const Boolean*>(shape.get())) {
            return std::make_shared<Boolean>(boolean->operation(), parts[0], parts[1]);
        }
        if (const auto* painted = dynamic_cast<const Painted*>(shape.get())) {
            return std::make_shared<Painted>(parts[0], painted->material());
        }
        return shape;
    }

    std::string_view structure_;
    std::unordered_map<const Shape*, ShapePointer> done_;
};

}  // namespace

Scene with_every_structure(const Scene& scene, std::string_view structure) {
    Scene copy;
    for (std::size_t i = 1; i < scene.materials().size(); ++i) {
        copy.add_material(scene.materials()[i]);
    }
    Rebuilder rebuild(structure);
    for (const SceneObject& object : scene.objects()) {
        copy.add_object(rebuild(object.shape), object.material, object.name);
    }
    for (const Light& light : scene.lights()) copy.add_light(light);
    copy.set_camera(scene.camera());
    copy.set_ambient(scene.ambient());
    copy.set_background(scene.background());
    SceneConfig config;
    config.accelerator = std::string(structure);
    copy.commit(config);
    return copy;
}

double structure_build_milliseconds(const Scene& scene) {
    double milliseconds = scene.accelerator_stats().build_milliseconds;
    std::unordered_set<const Shape*> seen;
    std::vector<const Shape*> stack;
    for (const SceneObject& object : scene.objects()) stack.push_back(object.shape.get());
    while (!stack.empty()) {
        const Shape* shape = stack.back();
        stack.pop_back();
        if (!seen.insert(shape).second) continue;
        if (const auto* mesh = dynamic_cast<const Mesh*>(shape)) {
            milliseconds += mesh->accelerator_stats().build_milliseconds;
        } else if (const auto* compound = dynamic_cast<const Compound*>(shape)) {
            milliseconds += compound->accelerator_stats().build_milliseconds;
        }
        for (const Shape* child : shape->children()) stack.push_back(child);
    }
    return milliseconds;
}

std::uint64_t cost_sum(const CostLayer& layer) {
    std::uint64_t sum = 0;
    for (const float cost : layer.total) sum += static_cast<std::uint64_t>(cost);
    return sum;
}

CostLayer cost_layer(const Scene& scene, const RenderSettings& settings,
                     std::string_view structure) {
    const Scene rebuilt = with_every_structure(scene, structure);
    const auto start = std::chrono::steady_clock::now();
    CostLayer layer = render_cost(rebuilt, settings);
    layer.trace_milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    layer.structure = std::string(structure);
    layer.build_milliseconds = structure_build_milliseconds(rebuilt);
    return layer;
}

std::vector<CostLayer> cost_layers(const Scene& scene, const RenderSettings& settings,
                                   const std::vector<std::string_view>& structures) {
    std::vector<CostLayer> layers;
    for (const std::string_view structure : structures) {
        layers.push_back(cost_layer(scene, settings, structure));
    }
    return layers;
}

}  // namespace csgrt
