#include "csgrt/csg/scene.h"

#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "csgrt/accel/built_at_commit.h"
#include "csgrt/core/error.h"
#include "csgrt/csg/shape_group.h"

namespace csgrt {

Scene::Scene() {
    materials_.push_back(Material{.name = "default", .albedo = Vector3(0.8, 0.8, 0.8)});
}

std::uint32_t Scene::add_material(Material material) {
    require_finite(material.albedo, "Scene", "material albedo");
    require((material.albedo.array() >= 0.0).all() && (material.albedo.array() <= 1.0).all(),
            "Scene", "material albedo", "in [0, 1]", material.albedo);
    materials_.push_back(std::move(material));
    return static_cast<std::uint32_t>(materials_.size() - 1);
}

std::uint32_t Scene::add_object(std::shared_ptr<const Shape> shape, std::uint32_t material,
                                std::string name) {
    require(shape != nullptr, "Scene", "object shape", "a shape", "null");
    require(material < materials_.size(), "Scene", "material",
            "an index below " + std::to_string(materials_.size()), material);
    require(objects_.size() < kNoIndex - 1, "Scene", "object count", "below 2^32 - 1",
            objects_.size());
    objects_.push_back(SceneObject{std::move(shape), material, std::move(name)});
    committed_ = false;
    hittable_ = false;
    group_.reset();
    return static_cast<std::uint32_t>(objects_.size() - 1);
}

namespace {

void require_area_light(const Vector3& radiance, int samples, std::string_view what) {
    require(radiance.allFinite() && (radiance.array() >= 0.0).all(), what, "radiance",
            "finite and >= 0", radiance);
    require(samples >= 1 && samples <= kMaxAreaLightSamples, what, "samples",
            "in [1, " + std::to_string(kMaxAreaLightSamples) + "]", samples);
}

}  // namespace

void Scene::add_light(Light light) {
    if (const auto* rectangle = std::get_if<RectangleLight>(&light)) {
        require_area_light(rectangle->radiance, rectangle->samples, "RectangleLight");
        const Vector3 normal = rectangle->edge_u.cross(rectangle->edge_v);
        require(rectangle->corner.allFinite() && normal.allFinite() && normal.norm() > 0.0,
                "RectangleLight", "edges", "finite and not parallel", normal);
    } else if (const auto* disk = std::get_if<DiskLight>(&light)) {
        require_area_light(disk->radiance, disk->samples, "DiskLight");
        require_positive(disk->radius, "DiskLight", "radius");
        require(disk->centre.allFinite() && disk->normal.allFinite() && disk->normal.norm() > 0.0,
                "DiskLight", "normal", "finite and non-zero", disk->normal);
    } else if (const auto* sphere = std::get_if<SphereLight>(&light)) {
        require_area_light(sphere->radiance, sphere->samples, "SphereLight");
        require_positive(sphere->radius, "SphereLight", "radius");
        require_finite(sphere->centre, "SphereLight", "centre");
    }
    lights_.push_back(std::move(light));
}

void Scene::set_camera(Camera camera) {
    camera_ = std::move(camera);
}

void Scene::set_ambient(const Vector3& ambient) {
    require(ambient.allFinite() && (ambient.array() >= 0.0).all(), "Scene", "ambient",
            "finite and >= 0", ambient);
    ambient_ = ambient;
}

void Scene::set_background(const Vector3& background) {
    require(background.allFinite() && (background.array() >= 0.0).all(), "Scene", "background",
            "finite and >= 0", background);
    background_ = background;
}

namespace {

/// Hands `config` to every shape below the objects that left its structure to the scene
/// (BuiltAtCommit: compounds made with build_at_commit), each shared shape once.
void build_below(const std::vector<SceneObject>& objects, const SceneConfig& config) {
    std::vector<const Shape*> pending;
    pending.reserve(objects.size());
    for (const SceneObject& object : objects) pending.push_back(object.shape.get());
    std::unordered_set<const Shape*> seen;
    while (!pending.empty()) {
        const Shape* shape = pending.back();
        pending.pop_back();
        std::vector<const Shape*> children = shape->children();
        // A leaf is reached once per placement and does nothing; only what has children
        // (instances, booleans, compounds) is remembered.
        if (!children.empty() && !seen.insert(shape).second) continue;
        if (const auto* deferred = dynamic_cast<const BuiltAtCommit*>(shape)) {
            deferred->build_at_commit(config.accelerator, config.accelerator_config);
        }
        pending.insert(pending.end(), children.begin(), children.end());
    }
}

}  // namespace

void Scene::commit(const SceneConfig& config) {
    committed_ = false;
    hittable_ = false;
    group_.reset();
    camera_.validate();
    build_below(objects_, config);
    std::vector<std::shared_ptr<const Shape>> shapes;
    shapes.reserve(objects_.size());
    for (const SceneObject& object : objects_) shapes.push_back(object.shape);
    auto group =
        std::make_shared<const ShapeGroup>(shapes, config.accelerator, config.accelerator_config,
                                           "requested in the scene configuration");
    std::string reason = group->accelerator_reason();
    if (!group->unbounded().empty()) {
        reason += "; " + std::to_string(group->unbounded().size()) +
                  " unbounded object(s) tested on every ray";
    }
    bounds_ = group->bounded_bounds();
    hittable_ = group->bounded().size() > 0 || !group->unbounded().empty();
    group_ = std::move(group);
    accelerator_reason_ = std::move(reason);
    committed_ = true;
}

std::optional<Hit> Scene::intersect(const Ray& ray, QueryScratch& scratch) const {
    if (!hittable_ || !is_valid(ray)) return std::nullopt;
    scratch.reset();
    HitRecord record;
    if (!group_->nearest(ray, record, scratch)) return std::nullopt;
    return finish_hit(ray, record, scratch);
}

std::optional<Hit> Scene::intersect_counted(const Ray& ray, QueryScratch& scratch,
                                            TraversalCounters& counters) const {
    if (!hittable_ || !is_valid(ray)) return std::nullopt;
    scratch.reset();
    HitRecord record;
    if (!group_->nearest_counted(ray, record, scratch, counters)) return std::nullopt;
    return finish_hit(ray, record, scratch);
}

bool Scene::occluded(const Ray& ray, QueryScratch& scratch) const {
    if (!hittable_ || !is_valid(ray)) return false;
    scratch.reset();
    return group_->any(ray, scratch);
}

std::string_view Scene::accelerator_name() const {
    return group_ ? group_->accelerator_name() : std::string_view();
}

AcceleratorStats Scene::accelerator_stats() const {
    return group_ ? group_->accelerator_stats() : AcceleratorStats{};
}

const ShapeGroup* Scene::group() const {
    return committed_ ? group_.get() : nullptr;
}

}  // namespace csgrt
