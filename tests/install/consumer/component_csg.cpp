// csgrt::csg alone: a scene file read from a string, a box minus a sphere at its centre; a ray
// along x from outside meets the box's face at x = -1 (t = 4), and a ray through the centre
// from inside the hole's sphere (radius 0.5) leaves the hole at t = 0.5.
#include <csgrt/csg/scene.h>
#include <csgrt/csg/scene_file.h>

#include <cstdio>

int main() {
    csgrt::Scene scene = csgrt::load_scene_from_string(R"({
      "objects": [{"type": "difference", "operands": [
          {"type": "box", "lower": [-1, -1, -1], "upper": [1, 1, 1]},
          {"type": "sphere", "center": [0, 0, 0], "radius": 0.5}]}]
    })",
                                                       "consumer.json");
    scene.commit();
    csgrt::QueryScratch scratch;
    csgrt::Ray outside;
    outside.origin = csgrt::Point3(-5, 0.9, 0);
    outside.direction = csgrt::Vector3(1, 0, 0);
    csgrt::Ray hole;
    hole.origin = csgrt::Point3(0, 0, 0);
    hole.direction = csgrt::Vector3(1, 0, 0);
    const auto face = scene.intersect(outside, scratch);
    const auto wall = scene.intersect(hole, scratch);
    if (!face || face->t != 4.0 || !wall || wall->t != 0.5) {
        std::printf("csg: expected t = 4 and t = 0.5\n");
        return 1;
    }
    std::printf("csg: t = %g, %g\n", face->t, wall->t);
    return 0;
}
