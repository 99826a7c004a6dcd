// csgrt::accel alone: a BVH over a two-triangle square in the plane z = 1 finds it at t = 1
// from the origin looking up z, and misses beside it. (The Mesh shape is csgrt::mesh's.)
#include <csgrt/accel/factory.h>
#include <csgrt/accel/triangle_set.h>
#include <csgrt/core/query_scratch.h>

#include <cstdio>
#include <vector>

int main() {
    const std::vector<Eigen::Vector3d> vertices = {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}, {0, 2, 3}};
    const csgrt::TriangleSet<float> square(vertices, triangles);
    const auto bvh = csgrt::make_accelerator("bvh", square);
    csgrt::QueryScratch scratch;
    csgrt::Ray ray;
    ray.origin = csgrt::Point3(0.25, 0.5, 0);
    ray.direction = csgrt::Vector3(0, 0, 1);
    csgrt::HitRecord hit;
    const bool found = bvh->intersect(ray, hit, scratch);
    ray.origin = csgrt::Point3(2, 0, 0);
    csgrt::HitRecord miss;
    if (!found || hit.t != 1.0 || bvh->intersect(ray, miss, scratch)) {
        std::printf("accel: expected a hit at t = 1 and then a miss\n");
        return 1;
    }
    std::printf("accel: t = %g\n", hit.t);
    return 0;
}
