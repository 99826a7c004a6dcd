// csgrt::core alone (Eigen only): a ray through a unit sphere hits it at t = 4, the distance
// from the origin (0, 0, -5) to the sphere's near pole, exactly representable.
#include <csgrt/core/shapes.h>

#include <cstdio>

int main() {
    const csgrt::Sphere sphere(csgrt::Point3(0, 0, 0), 1.0);
    csgrt::Ray ray;
    ray.origin = csgrt::Point3(0, 0, -5);
    ray.direction = csgrt::Vector3(0, 0, 1);
    const auto hit = sphere.intersect(ray);
    if (!hit || hit->t != 4.0) {
        std::printf("core: expected t = 4, got %s\n",
                    hit ? std::to_string(hit->t).c_str() : "none");
        return 1;
    }
    std::printf("core: t = %g\n", hit->t);
    return 0;
}
