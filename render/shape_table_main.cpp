// Prints one row per shape: a fixed, seeded set of rays aimed at its bounds, how many hit, the
// mean nearest t, and throughput. The README's main job until the renderer lands.
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "csgrt/core/shapes.h"

namespace {

struct Row {
    const char* name;
    std::shared_ptr<const csgrt::Shape> shape;
};

std::vector<csgrt::Ray> rays_toward(const csgrt::Aabb& box, int count) {
    std::mt19937_64 engine(1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const csgrt::Aabb target = box.is_finite() ? box : csgrt::Aabb({-1, -1, -1}, {1, 1, 1});
    const double radius = 2.0 * target.diagonal().norm();
    std::vector<csgrt::Ray> rays;
    for (int i = 0; i < count; ++i) {
        const csgrt::Vector3 from(unit(engine) - 0.5, unit(engine) - 0.5, unit(engine) - 0.5);
        const csgrt::Point3 aim = target.lower + target.diagonal().cwiseProduct(csgrt::Vector3(
                                                     unit(engine), unit(engine), unit(engine)));
        const csgrt::Point3 origin = target.center() + from.normalized() * radius;
        rays.push_back(csgrt::Ray{origin, aim - origin});
    }
    return rays;
}

}  // namespace

int main() {
    using namespace csgrt;
    const std::vector<Row> rows = {
        {"sphere", std::make_shared<Sphere>(Point3(0, 0, 0), 1.0)},
        {"instance(sphere)",
         std::make_shared<Instance>(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0),
                                    Transform::scale(Vector3(2, 1, 0.5)))},
    };
    constexpr int kRays = 200000;
    std::printf("%-28s %10s %8s %12s %10s\n", "shape", "rays", "hit %", "mean t", "Mrays/s");
    for (const Row& row : rows) {
        const std::vector<Ray> rays = rays_toward(row.shape->bounds(), kRays);
        QueryScratch scratch;
        int hits = 0;
        double sum_t = 0.0;
        const auto start = std::chrono::steady_clock::now();
        for (const Ray& ray : rays) {
            scratch.reset();
            HitRecord record;
            if (row.shape->nearest_hit(ray, record, scratch)) {
                ++hits;
                sum_t += record.t;
            }
        }
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::printf("%-28s %10d %8.2f %12.5f %10.2f\n", row.name, kRays, 100.0 * hits / kRays,
                    hits ? sum_t / hits : 0.0, kRays / seconds * 1e-6);
    }
    return 0;
}
