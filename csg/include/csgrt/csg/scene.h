#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/accelerator_config.h"
#include "csgrt/accel/factory.h"
#include "csgrt/core/shape.h"
#include "csgrt/csg/camera.h"

namespace csgrt {

class ShapeGroup;

/// A Lambertian surface colour (linear RGB albedo in [0, 1]).
struct Material {
    std::string name;
    Vector3 albedo{0.8, 0.8, 0.8};
    /// Normalised Phong specular colour added to the Lambert term (render/materials.h; 0: none;
    /// albedo + specular <= 1 per channel conserves energy), and its exponent.
    Vector3 specular{0.0, 0.0, 0.0};
    double shininess = 32.0;
    /// Perfect-mirror reflectance per channel (0: none), traced to RenderSettings::max_depth.
    Vector3 mirror{0.0, 0.0, 0.0};
    /// Index of refraction of a dielectric (glass 1.5): reflects and refracts by Fresnel's
    /// equations, total internal reflection included, instead of the terms above. 0: opaque.
    double ior = 0.0;
};

/// Light from a point, falling off with the squared distance.
struct PointLight {
    Point3 position{0.0, 10.0, 0.0};
    /// Linear RGB intensity (radiance times squared distance).
    Vector3 intensity{100.0, 100.0, 100.0};
    /// The exponent k of the falloff, irradiance = intensity / distance^k: 2 is physical;
    /// 1 and 0 match renderers whose lights fade linearly or not at all.
    double falloff = 2.0;
};

/// Light from infinitely far away, arriving along `direction` (the way the light travels).
struct DirectionalLight {
    Vector3 direction{0.0, -1.0, 0.0};
    Vector3 radiance{1.0, 1.0, 1.0};
};

/// Samples per area light by default, and the most a light may ask for.
inline constexpr int kDefaultAreaLightSamples = 16;
inline constexpr int kMaxAreaLightSamples = 4096;

/// A parallelogram (a rectangle when the edges are perpendicular) emitting `radiance` from the
/// side edge_u x edge_v points to: the points corner + a edge_u + b edge_v, a, b in [0, 1].
/// Shadows are soft: `samples` shadow rays, stratified over its area (render/lights.h).
struct RectangleLight {
    Point3 corner{-0.5, 10.0, -0.5};
    Vector3 edge_u{1.0, 0.0, 0.0};
    Vector3 edge_v{0.0, 0.0, 1.0};
    /// Linear RGB radiance, the same at every point and in every direction it emits to.
    Vector3 radiance{10.0, 10.0, 10.0};
    int samples = kDefaultAreaLightSamples;
};

/// A disk emitting `radiance` from the side `normal` points to, sampled like RectangleLight.
struct DiskLight {
    Point3 centre{0.0, 10.0, 0.0};
    Vector3 normal{0.0, -1.0, 0.0};
    double radius = 1.0;
    Vector3 radiance{10.0, 10.0, 10.0};
    int samples = kDefaultAreaLightSamples;
};

/// A ball emitting `radiance` outward from its surface, sampled over the cone of directions it
/// fills as seen from the point lit (render/lights.h).
struct SphereLight {
    Point3 centre{0.0, 10.0, 0.0};
    double radius = 1.0;
    Vector3 radiance{10.0, 10.0, 10.0};
    int samples = kDefaultAreaLightSamples;
};

using Light = std::variant<PointLight, DirectionalLight, RectangleLight, DiskLight, SphereLight>;

/// One top-level object of a scene.
struct SceneObject {
    std::shared_ptr<const Shape> shape;
    std::uint32_t material = 0;
    std::string name;
};

/// How `commit` organises the top-level objects, and the compounds below them that leave their
/// structure to the scene (CompoundConfig::build_at_commit).
struct SceneConfig {
    /// "auto" (the documented rule in docs/scene.md), or a structure name known to
    /// make_accelerator ("brute", "bvh", "grid", "hgrid", "rayclass").
    std::string accelerator = "auto";
    AcceleratorConfig accelerator_config;
};

/// A scene: objects (any shape: primitives, instances, booleans, compounds, meshes), materials,
/// lights and a camera. Follows the add -> commit -> query lifecycle: `commit` computes the
/// bounds and builds the structure over the objects (unbounded objects such as planes are kept
/// apart and tested on every ray); queries after that are const and thread-safe, each thread
/// bringing its own QueryScratch. Adding after commit requires another commit.
class Scene {
public:
    Scene();

    /// Material 0 always exists: a neutral grey named "default". Returns the new material's
    /// index. Throws InvalidParameter for an albedo outside [0, 1].
    std::uint32_t add_material(Material material);
    /// Returns the object's index (its object id in hits and in the renderer's id channel).
    /// Throws InvalidParameter for a null shape or an unknown material.
    std::uint32_t add_object(std::shared_ptr<const Shape> shape, std::uint32_t material = 0,
                             std::string name = {});
    /// Throws InvalidParameter for an area light with a sample count outside
    /// [1, kMaxAreaLightSamples], a non-finite or negative radiance, a radius <= 0, parallel
    /// rectangle edges or a zero disk normal.
    void add_light(Light light);
    void set_camera(Camera camera);
    /// Linear radiance arriving at every surface from every direction, unshadowed: the
    /// renderer adds albedo * ambient to each opaque surface (classic renderers' ambient term).
    /// Throws InvalidParameter unless finite and >= 0 per channel.
    void set_ambient(const Vector3& ambient);
    /// Linear radiance of rays that hit nothing (camera, mirror and glass rays). Throws
    /// InvalidParameter unless finite and >= 0 per channel.
    void set_background(const Vector3& background);

    /// Builds everything queries need: validates the camera, builds the structures below the
    /// objects that were left to it (compounds made with build_at_commit: `config`'s structure
    /// name where theirs is "auto", its AcceleratorConfig), computes the bounds, and builds the
    /// objects' ShapeGroup (csg/shape_group.h), a structure over the bounded objects ("auto":
    /// choose_accelerator in accel/factory.h, documented in docs/scene.md). Throws
    /// InvalidParameter for an invalid camera or an unknown structure name; the scene is then left
    /// uncommitted.
    void commit(const SceneConfig& config = {});
    bool is_committed() const { return committed_; }

    /// Nearest hit with t in [t_min, t_max], finished, with object_id set; nothing for an
    /// invalid ray or an uncommitted scene.
    std::optional<Hit> intersect(const Ray& ray, QueryScratch& scratch) const;
    /// The same, counting the top-level structure's work into `counters`.
    std::optional<Hit> intersect_counted(const Ray& ray, QueryScratch& scratch,
                                         TraversalCounters& counters) const;
    /// Whether anything is hit in [t_min, t_max] (shadow rays).
    bool occluded(const Ray& ray, QueryScratch& scratch) const;

    const std::vector<SceneObject>& objects() const { return objects_; }
    const std::vector<Material>& materials() const { return materials_; }
    const std::vector<Light>& lights() const { return lights_; }
    const Camera& camera() const { return camera_; }
    const Vector3& ambient() const { return ambient_; }
    const Vector3& background() const { return background_; }
    /// World bounds of the bounded objects (valid after commit).
    const Aabb& bounds() const { return bounds_; }

    /// The structure commit chose over the top-level objects, and why (for `csgrt info`).
    std::string_view accelerator_name() const;
    const std::string& accelerator_reason() const { return accelerator_reason_; }
    AcceleratorStats accelerator_stats() const;
    /// The committed objects as a group (member index = object index), for queries built on
    /// the scene's structure; null before commit.
    const ShapeGroup* group() const;

private:
    std::vector<SceneObject> objects_;
    std::vector<Material> materials_;
    std::vector<Light> lights_;
    Camera camera_;
    Vector3 ambient_{0.0, 0.0, 0.0};
    Vector3 background_{0.0, 0.0, 0.0};
    Aabb bounds_;
    bool committed_ = false;
    /// Whether the committed scene has any object a ray could hit: without one every query
    /// answers at once, so an empty frame costs only its camera rays (issue 13's fixed cost).
    bool hittable_ = false;
    std::string accelerator_reason_;
    /// Held by shared_ptr so a Scene stays cheap to copy (copies share the built structure).
    std::shared_ptr<const ShapeGroup> group_;
};

}  // namespace csgrt
