// csgrt::mesh alone: a BVH over a two-triangle square in the plane z = 1
// finds it at t = 1 from the origin looking up z, and misses beside it.
#include <csgrt/mesh/mesh.h>

#include <cstdio>

int main() {
    csgrt::TriangleMeshData square;
    square.vertices = {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}};
    square.triangles = {{0, 1, 2}, {0, 2, 3}};
    csgrt::MeshConfig config;
    config.accelerator = "bvh";
    const csgrt::Mesh mesh(square, config);
    csgrt::Ray ray;
    ray.origin = csgrt::Point3(0.25, 0.5, 0);
    ray.direction = csgrt::Vector3(0, 0, 1);
    const auto hit = mesh.intersect(ray);
    ray.origin = csgrt::Point3(2, 0, 0);
    if (!hit || hit->t != 1.0 || mesh.intersect(ray)) {
        std::printf("mesh: expected a hit at t = 1 and then a miss\n");
        return 1;
    }
    std::printf("mesh: t = %g\n", hit->t);
    return 0;
}
