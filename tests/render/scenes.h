#pragma once

#include <memory>
#include <string>

#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/scene.h"
#include "csgrt/render/renderer.h"

namespace csgrt::test {

/// Gives `scene` a pinhole camera at `position` looking at `look_at` (the default field of
/// view unless one is given, in degrees, vertically).
inline void set_view(Scene& scene, const Point3& position, const Point3& look_at,
                     double vertical_fov_degrees = Camera{}.vertical_fov_degrees) {
    Camera camera;
    camera.position = position;
    camera.look_at = look_at;
    camera.vertical_fov_degrees = vertical_fov_degrees;
    scene.set_camera(camera);
}

/// Default render settings for an image of width x height pixels, `samples` a pixel.
inline RenderSettings settings_of_size(int width, int height, int samples = 1) {
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.samples_per_pixel = samples;
    return settings;
}

/// Gives `scene` an orthographic camera at `position` looking at `look_at`, whose view is
/// `height` tall.
inline void set_orthographic_view(Scene& scene, const Point3& position, const Point3& look_at,
                                  double height) {
    Camera camera;
    camera.projection = Camera::Projection::Orthographic;
    camera.position = position;
    camera.look_at = look_at;
    camera.orthographic_height = height;
    scene.set_camera(camera);
}

/// Three spheres of different colours on a ground plane (y = 0), lit by a point light and a
/// directional light: shading, hard shadows and object ids in one small scene.
inline Scene spheres_on_a_plane() {
    Scene scene;
    const auto red = scene.add_material(Material{"red", Vector3(0.8, 0.2, 0.2)});
    const auto green = scene.add_material(Material{"green", Vector3(0.2, 0.7, 0.3)});
    const auto blue = scene.add_material(Material{"blue", Vector3(0.2, 0.3, 0.9)});
    scene.add_object(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 1, 0)), 0, "ground");
    scene.add_object(std::make_shared<Sphere>(Point3(-1.2, 0.6, 0.0), 0.6), red, "left");
    scene.add_object(std::make_shared<Sphere>(Point3(0.2, 0.9, -0.6), 0.9), green, "middle");
    scene.add_object(std::make_shared<Sphere>(Point3(1.4, 0.4, 0.7), 0.4), blue, "right");
    scene.add_light(PointLight{Point3(-3, 6, 4), Vector3(150, 150, 150)});
    scene.add_light(DirectionalLight{Vector3(0.4, -1.0, -0.3), Vector3(1.5, 1.4, 1.2)});
    test::set_view(scene, Point3(0.5, 2.5, 6.0), Point3(0.0, 0.6, 0.0), 40.0);
    return scene;
}

/// CSG: a box with a spherical bite and a cylindrical hole, and a union of two spheres,
/// seen by an orthographic camera, with one point light.
inline Scene csg_solids() {
    Scene scene;
    const auto orange = scene.add_material(Material{"orange", Vector3(0.9, 0.5, 0.1)});
    const auto white = scene.add_material(Material{"white", Vector3(0.9, 0.9, 0.9)});
    auto box = std::make_shared<Box>(Point3(-1, -1, -1), Point3(1, 1, 1));
    auto bite = std::make_shared<Sphere>(Point3(1, 1, 1), 1.0);
    auto hole = std::make_shared<Instance>(std::make_shared<Cylinder>(0.4, -2.0, 2.0, true),
                                           Transform::rotate(Vector3(1, 0, 0), kPi / 2));
    scene.add_object(make_difference(box, {bite, hole}), orange, "carved box");
    auto a = std::make_shared<Sphere>(Point3(2.2, 0.0, 0.0), 0.7);
    auto b = std::make_shared<Sphere>(Point3(2.7, 0.5, 0.2), 0.5);
    scene.add_object(make_union({a, b}), white, "blob");
    scene.add_light(PointLight{Point3(3, 5, 6), Vector3(200, 200, 200)});
    test::set_orthographic_view(scene, Point3(2.5, 2.0, 5.0), Point3(0.9, 0.1, 0.0), 4.8);
    return scene;
}

/// An n x n x n lattice of small spheres and no lights (eye light): many objects, so the
/// structure over them matters.
inline Scene sphere_lattice(int n) {
    Scene scene;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            for (int k = 0; k < n; ++k) {
                scene.add_object(std::make_shared<Sphere>(Point3(i, j, k), 0.3));
            }
        }
    }
    Camera camera;
    camera.position = Point3(-0.7 * n, 0.4 * n, 2.2 * n);
    camera.look_at = Point3(0.5 * (n - 1), 0.5 * (n - 1), 0.5 * (n - 1));
    scene.set_camera(camera);
    return scene;
}

}  // namespace csgrt::test
