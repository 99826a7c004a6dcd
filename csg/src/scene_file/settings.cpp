// The scene's settings: the camera, the materials, the lights, the ambient and background
// colours, each value checked at its key (docs/scene-format.md).

#include <Eigen/Geometry>
#include <cfloat>
#include <cstdio>

#include "csgrt/core/error.h"
#include "limits.h"
#include "loader.h"

namespace csgrt::detail::scene_file {

namespace {

/// Fails at `key` of `fields` unless |v|^2 is finite (and, for a direction, not zero when v
/// is not): the shading and the camera square lengths and normalise.
void require_length(const Vector3& v, Fields& fields, std::string_view key, std::string_view what,
                    bool direction) {
    // stableNorm scales first, so the length it reports is the true one, not an overflow.
    const double length = v.stableNorm();
    if (!(length <= kMaxLength)) {
        char text[32];
        std::snprintf(text, sizeof text, "%.6g", length);
        fields.fail(key, std::string(what) + " has length " + text +
                             ", beyond 1e150: its square overflows a double in the shading");
    }
    if (direction && v.squaredNorm() < DBL_MIN) {
        fields.fail(key, std::string(what) + " " + detail::describe(v) +
                             " is too short: its square underflows a double, so it has no "
                             "direction");
    }
}

}  // namespace

void Loader::camera(Scene& scene) {
    Camera camera;
    if (root_.contains("camera")) {
        Fields fields(root_.at("camera"), JsonPointer().child("camera"), source_, "the camera");
        const std::string projection = fields.string("projection", "pinhole");
        if (projection == "orthographic") {
            camera.projection = Camera::Projection::Orthographic;
        } else if (projection != "pinhole") {
            fields.fail("projection",
                        "expected \"pinhole\" or \"orthographic\", got " + quote_name(projection));
        }
        camera.position = fields.vector("position", camera.position);
        camera.look_at = fields.vector("look_at", camera.look_at);
        camera.up = fields.vector("up", camera.up);
        camera.vertical_fov_degrees =
            fields.number("vertical_fov_degrees", camera.vertical_fov_degrees);
        camera.orthographic_height =
            fields.number("orthographic_height", camera.orthographic_height);
        fields.finish();
        require_length(camera.position, fields, "position", "the position", false);
        require_length(camera.look_at, fields, "look_at", "look_at", false);
        require_length(camera.up, fields, "up", "the up vector", true);
        // look_at == position is Camera::validate's to report.
        if (camera.look_at != camera.position) {
            require_length(camera.look_at - camera.position, fields, "look_at",
                           "the view direction look_at - position", true);
        }
        try {
            camera.validate();
        } catch (const InvalidParameter& error) {
            rethrow_invalid(error, fields, root_.at("camera"), false);
        }
    }
    scene.set_camera(camera);
}

void Loader::materials(Scene& scene, std::map<std::string, std::uint32_t>& by_name) {
    by_name["default"] = 0;
    if (!root_.contains("materials")) return;
    const Json& materials = root_.at("materials");
    if (!materials.is_object()) {
        source_.fail(std::string("/materials"),
                     "expected an object of named materials, got " + describe(materials));
    }
    for (auto it = materials.begin(); it != materials.end(); ++it) {
        const JsonPointer at = JsonPointer().child("materials").child(it.key());
        if (it.key() == "default") {
            source_.fail(at, "the name \"default\" is taken by material 0, the neutral grey");
        }
        Fields fields(it.value(), at, source_, "a material");
        Material material{it.key(), fields.colour("albedo", Vector3(0.8, 0.8, 0.8))};
        // Secondary-ray terms (render/materials.h, docs/scene-format.md): each checked here.
        material.specular = fields.colour("specular", material.specular);
        material.mirror = fields.colour("mirror", material.mirror);
        for (const char* key : {"specular", "mirror"}) {
            const Vector3& colour = key[0] == 's' ? material.specular : material.mirror;
            if (!((colour.array() >= 0.0) && (colour.array() <= 1.0)).all()) {
                fields.fail(key, "expected values in [0, 1], got " + detail::describe(colour));
            }
        }
        material.shininess = fields.number("shininess", material.shininess);
        if (!(material.shininess >= 0.0 && material.shininess <= 1e6)) {
            fields.fail("shininess", "expected a Phong exponent in [0, 1e6], got " +
                                         detail::describe(material.shininess));
        }
        material.ior = fields.number("ior", material.ior);
        if (!(material.ior == 0.0 || (material.ior >= 1.0 && material.ior <= 10.0))) {
            fields.fail("ior", "expected 0 (opaque) or an index of refraction in [1, 10], got " +
                                   detail::describe(material.ior));
        }
        fields.finish();
        try {
            by_name[it.key()] = scene.add_material(material);
        } catch (const InvalidParameter& error) {
            source_.fail(at.child("albedo"), error.what());
        }
    }
}

void Loader::lights(Scene& scene) {
    if (!root_.contains("lights")) return;
    const Json& lights = root_.at("lights");
    if (!lights.is_array()) {
        source_.fail(std::string("/lights"),
                     "expected an array of lights, got " + describe(lights));
    }
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const JsonPointer at = JsonPointer().child("lights").child(i);
        Fields fields(lights[i], at, source_, "a light");
        const std::string type = fields.string("type");
        auto check_colour = [&](std::string_view key, const Vector3& colour) {
            if (!(colour.array() >= 0.0).all()) {
                fields.fail(key, "expected values >= 0, got " + detail::describe(colour));
            }
            if (!(colour.array() <= kMaxIntensity).all()) {
                fields.fail(key, "expected values <= " + detail::describe(kMaxIntensity) +
                                     " (brighter overflows the image's float pixels), got " +
                                     detail::describe(colour));
            }
        };
        if (type == "point") {
            fields.set_what("a point light");
            PointLight light;
            light.position = fields.vector("position");
            require_length(light.position, fields, "position", "the position", false);
            light.intensity = fields.colour("intensity", light.intensity);
            check_colour("intensity", light.intensity);
            light.falloff = fields.number("falloff", light.falloff);
            if (!(light.falloff >= 0.0 && light.falloff <= 4.0)) {
                fields.fail("falloff", "expected an exponent in [0, 4] (2: 1/d^2), got " +
                                           detail::describe(light.falloff));
            }
            scene.add_light(light);
        } else if (type == "directional") {
            fields.set_what("a directional light");
            DirectionalLight light;
            light.direction = fields.vector("direction");
            if ((light.direction.array() == 0.0).all()) {
                fields.fail("direction", "expected a non-zero direction, got (0, 0, 0)");
            }
            require_length(light.direction, fields, "direction", "the direction", true);
            light.radiance = fields.colour("radiance", light.radiance);
            check_colour("radiance", light.radiance);
            scene.add_light(light);
        } else if (type == "rectangle" || type == "disk" || type == "sphere") {
            // Area lights (render/lights.h): a radiance and a count of stratified samples.
            fields.set_what("a " + type + " light");
            const Vector3 radiance = fields.colour("radiance", Vector3::Constant(10.0));
            check_colour("radiance", radiance);
            int samples = kDefaultAreaLightSamples;
            if (fields.has("samples")) {
                const std::size_t count = fields.count("samples");
                if (count < 1 || count > static_cast<std::size_t>(kMaxAreaLightSamples)) {
                    fields.fail("samples", "expected a sample count in [1, " +
                                               std::to_string(kMaxAreaLightSamples) + "], got " +
                                               std::to_string(count));
                }
                samples = static_cast<int>(count);
            }
            auto positive_radius = [&] {
                const double radius = fields.number("radius", 1.0);
                if (!(radius > 0.0 && radius <= kMaxLength)) {
                    fields.fail("radius",
                                "expected a radius in (0, 1e150], got " + detail::describe(radius));
                }
                return radius;
            };
            if (type == "rectangle") {
                RectangleLight light{.radiance = radiance, .samples = samples};
                light.corner = fields.vector("corner");
                require_length(light.corner, fields, "corner", "the corner", false);
                for (const char* key : {"edge_u", "edge_v"}) {
                    Vector3& edge = key[5] == 'u' ? light.edge_u : light.edge_v;
                    edge = fields.vector(key);
                    require_length(edge, fields, key, "the edge", true);
                }
                const Vector3 normal = light.edge_u.cross(light.edge_v);
                if (!(normal.norm() > 1e-12 * light.edge_u.norm() * light.edge_v.norm())) {
                    fields.fail("edge_v", "expected an edge not parallel to edge_u, got " +
                                              detail::describe(light.edge_v));
                }
                scene.add_light(light);
            } else if (type == "disk") {
                DiskLight light{.radiance = radiance, .samples = samples};
                light.centre = fields.vector("center");
                require_length(light.centre, fields, "center", "the center", false);
                light.normal = fields.vector("normal");
                require_length(light.normal, fields, "normal", "the normal", true);
                light.radius = positive_radius();
                scene.add_light(light);
            } else {
                SphereLight light{.radiance = radiance, .samples = samples};
                light.centre = fields.vector("center");
                require_length(light.centre, fields, "center", "the center", false);
                light.radius = positive_radius();
                scene.add_light(light);
            }
        } else {
            fields.fail("type",
                        "expected \"point\" or \"directional\", or an area light "
                        "\"rectangle\", \"disk\" or \"sphere\", got " +
                            quote_name(type));
        }
        fields.finish();
    }
}

/// The top-level "ambient" and "background" colours (docs/scene-format.md): linear radiance,
/// each channel in [0, kMaxIntensity].
void Loader::ambient_and_background(Scene& scene) {
    Fields fields(root_, JsonPointer(), source_, "the scene");
    for (const char* key : {"ambient", "background"}) {
        if (!root_.contains(key)) continue;
        const Vector3 colour = fields.colour(key, Vector3::Zero());
        if (!((colour.array() >= 0.0) && (colour.array() <= kMaxIntensity)).all()) {
            fields.fail(key, "expected values in [0, " + detail::describe(kMaxIntensity) +
                                 "] (linear radiance), got " + detail::describe(colour));
        }
        if (key[0] == 'a')
            scene.set_ambient(colour);
        else
            scene.set_background(colour);
    }
}

}  // namespace csgrt::detail::scene_file
