#include "csgrt/csg/scene.h"

#include <string>
#include <utility>

#include "csgrt/accel/shape_set.h"
#include "csgrt/core/error.h"
#include "csgrt/csg/compound.h"

namespace csgrt {

/// What commit builds. Held by shared_ptr so a Scene stays cheap to copy; the structure refers
/// to `set`, so this never moves once built.
struct Scene::Committed {
    /// The bounded objects, in object order, and the object index of each set member.
    ShapeSet set;
    std::vector<std::uint32_t> set_object;
    std::unique_ptr<Accelerator<ShapeSet>> structure;
    /// Objects with an infinite box (planes), by object index, tested on every ray.
    std::vector<std::uint32_t> unbounded;
};

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
    committed_state_.reset();
    return static_cast<std::uint32_t>(objects_.size() - 1);
}

void Scene::add_light(Light light) {
    lights_.push_back(std::move(light));
}

void Scene::set_camera(Camera camera) {
    camera_ = std::move(camera);
}

void Scene::commit(const SceneConfig& config) {
    committed_ = false;
    committed_state_.reset();
    camera_.validate();
    auto state = std::make_shared<Committed>();
    std::vector<std::shared_ptr<const Shape>> bounded;
    Aabb bounds;
    for (std::size_t i = 0; i < objects_.size(); ++i) {
        const Aabb box = objects_[i].shape->bounds();
        // An object with an empty box (an empty compound) can never be hit.
        if (box.is_empty()) continue;
        if (box.is_finite()) {
            bounded.push_back(objects_[i].shape);
            state->set_object.push_back(static_cast<std::uint32_t>(i));
            bounds.extend(box);
        } else {
            state->unbounded.push_back(static_cast<std::uint32_t>(i));
        }
    }
    state->set = ShapeSet(std::move(bounded));
    std::string reason;
    std::string name = config.accelerator;
    if (name == "auto") {
        name = choose_accelerator(state->set.size(), reason);
    } else {
        reason = "requested in the scene configuration";
    }
    state->structure = make_accelerator(name, state->set, config.accelerator_config);
    if (!state->unbounded.empty()) {
        reason += "; " + std::to_string(state->unbounded.size()) +
                  " unbounded object(s) tested on every ray";
    }
    committed_state_ = std::move(state);
    bounds_ = bounds;
    accelerator_reason_ = std::move(reason);
    committed_ = true;
}

namespace {

template <bool kCount>
bool nearest(const Ray& ray, HitRecord& best, QueryScratch& scratch,
             const Accelerator<ShapeSet>& structure, const std::vector<std::uint32_t>& set_object,
             const std::vector<std::uint32_t>& unbounded, const std::vector<SceneObject>& objects,
             TraversalCounters& counters) {
    bool found = kCount ? structure.intersect_counted(ray, best, scratch, counters)
                        : structure.intersect(ray, best, scratch);
    if (found) best.object = set_object[best.object];
    for (const std::uint32_t index : unbounded) {
        Ray narrowed = ray;
        if (found) narrowed.t_max = best.t;
        HitRecord candidate;
        if constexpr (kCount) ++counters.primitives_tested;
        if (!objects[index].shape->nearest_hit(narrowed, candidate, scratch)) continue;
        // The structure's tie rule (lower member index) extended to the whole object list.
        if (found && !(candidate.t < best.t || (candidate.t == best.t && index < best.object)))
            continue;
        best = candidate;
        best.object = index;
        found = true;
    }
    return found;
}

}  // namespace

std::optional<Hit> Scene::intersect(const Ray& ray, QueryScratch& scratch) const {
    TraversalCounters unused;
    if (!committed_ || !is_valid(ray)) return std::nullopt;
    scratch.reset();
    const Committed& state = *committed_state_;
    HitRecord record;
    if (!nearest<false>(ray, record, scratch, *state.structure, state.set_object, state.unbounded,
                        objects_, unused))
        return std::nullopt;
    return finish_hit(ray, record, scratch);
}

std::optional<Hit> Scene::intersect_counted(const Ray& ray, QueryScratch& scratch,
                                            TraversalCounters& counters) const {
    if (!committed_ || !is_valid(ray)) return std::nullopt;
    scratch.reset();
    const Committed& state = *committed_state_;
    HitRecord record;
    if (!nearest<true>(ray, record, scratch, *state.structure, state.set_object, state.unbounded,
                       objects_, counters))
        return std::nullopt;
    return finish_hit(ray, record, scratch);
}

bool Scene::occluded(const Ray& ray, QueryScratch& scratch) const {
    if (!committed_ || !is_valid(ray)) return false;
    scratch.reset();
    const Committed& state = *committed_state_;
    if (state.structure->occluded(ray, scratch)) return true;
    for (const std::uint32_t index : state.unbounded) {
        if (objects_[index].shape->any_hit(ray, scratch)) return true;
    }
    return false;
}

std::string_view Scene::accelerator_name() const {
    return committed_state_ ? committed_state_->structure->name() : std::string_view();
}

AcceleratorStats Scene::accelerator_stats() const {
    return committed_state_ ? committed_state_->structure->stats() : AcceleratorStats{};
}

}  // namespace csgrt
