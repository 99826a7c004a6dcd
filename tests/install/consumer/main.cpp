// The program of docs/api.md: a CSG scene built in code, rendered, written as EXR + PNGs.
#include <csgrt/core/shapes.h>
#include <csgrt/csg/boolean.h>
#include <csgrt/csg/scene.h>
#include <csgrt/render/exr.h>
#include <csgrt/render/renderer.h>

#include <cstdio>
#include <memory>
#include <string>

int main(int argc, char** argv) {
    using namespace csgrt;
    Scene scene;
    const auto orange = scene.add_material(Material{"orange", Vector3(0.9, 0.45, 0.1)});
    auto cube = std::make_shared<Box>(Point3(-1, -1, -1), Point3(1, 1, 1));
    auto ball = std::make_shared<Sphere>(Point3(0, 0, 0), 1.35);
    auto drill = std::make_shared<Cylinder>(0.5, -2.0, 2.0, true);  // along y
    scene.add_object(make_difference(make_intersection({cube, ball}), {drill}), orange, "nut");
    scene.add_object(std::make_shared<Plane>(Point3(0, -1, 0), Normal3(0, 1, 0)), 0, "floor");
    scene.add_light(PointLight{Point3(3, 6, 4), Vector3(400, 400, 400)});
    Camera camera;
    camera.position = Point3(3, 3, 5);
    camera.look_at = Point3(0, -0.3, 0);
    scene.set_camera(camera);
    scene.commit();

    RenderSettings settings;
    settings.width = 320;
    settings.height = 240;
    settings.samples_per_pixel = 4;
    const RenderResult result = render(scene, settings);
    ExrMetadata metadata;  // what the EXR header records besides the pixels
    metadata.camera = camera;
    metadata.accelerator = scene.accelerator_name();
    write_render_files(argc > 1 ? argv[1] : "nut.exr", result.image, metadata);  // + .png files
    std::printf("%.3f s, %.2f Mrays/s\n", result.stats.seconds,
                result.stats.million_rays_per_second());
}
