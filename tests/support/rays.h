#pragma once

// Seeded ray sets shared by the structure tests: camera-like, incoherent and axis-parallel
// rays around a scene's box.

#include <algorithm>
#include <array>
#include <vector>

#include "csgrt/core/aabb.h"
#include "csgrt/core/ray.h"
#include "support/meshes.h"
#include "support/random.h"

namespace csgrt::test {

/// The box of a list of points (a mesh's vertices).
inline Aabb bounds_of(const std::vector<Eigen::Vector3d>& points) {
    Aabb box;
    for (const Eigen::Vector3d& p : points) box.extend(p);
    return box;
}

/// The box of a mesh's vertices.
inline Aabb mesh_bounds(const TestMesh& mesh) {
    return bounds_of(mesh.vertices);
}

/// Gives some rays a finite interval: t_max cut at a random point, t_min moved forward or to
/// -infinity, so both ends of [t_min, t_max] are exercised.
inline void random_interval(Random& random, Ray& ray) {
    switch (random.integer(0, 5)) {
        case 0:
            ray.t_max = random.uniform(0.0, 2.0);
            break;
        case 1:
            ray.t_min = random.uniform(0.0, 1.0);
            break;
        case 2:
            ray.t_min = -kInfinity;
            break;
        case 3:
            ray.t_min = random.uniform(-1.0, 1.0);
            ray.t_max = ray.t_min + random.uniform(0.0, 2.0);
            break;
        default:
            break;
    }
}

/// `count` rays, the i-th made by `make(random, i)` from one seeded Random, every fourth then
/// given a random interval (random_interval).
template <class Make>
std::vector<Ray> seeded_rays(int count, std::uint64_t seed, Make&& make) {
    Random random(seed);
    std::vector<Ray> rays;
    rays.reserve(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
        rays.push_back(make(random, i));
        if (i % 4 == 0) random_interval(random, rays.back());
    }
    return rays;
}

/// Camera-like rays: from points on a shell around `box` (1 to 2 box sizes out) toward random
/// points of the box.
inline std::vector<Ray> camera_rays(const Aabb& box, int count, std::uint64_t seed) {
    const double size = box.diagonal().norm();
    return seeded_rays(count, seed, [&](Random& random, int) {
        const Point3 eye = box.center() + random.unit_vector() * size * random.uniform(1.0, 2.0);
        const Point3 target = random.in_box(box);
        return Ray{eye, (target - eye) * random.uniform(0.25, 4.0) / size};
    });
}

/// Incoherent rays: random origins in and around `box` (half of them inside), random
/// directions of random length.
inline std::vector<Ray> incoherent_rays(const Aabb& box, int count, std::uint64_t seed) {
    const Aabb around = enlarged(box, 0.5);
    return seeded_rays(count, seed, [&](Random& random, int i) {
        const Point3 origin = random.in_box(i % 2 ? box : around);
        return Ray{origin, random.unit_vector() * random.uniform(0.25, 4.0)};
    });
}

/// Rays parallel to the axes (exact zero components), from random points in and around `box`.
inline std::vector<Ray> axis_rays(const Aabb& box, int count, std::uint64_t seed) {
    Random random(seed);
    std::vector<Ray> rays;
    const Aabb around = enlarged(box, 0.2);
    for (int i = 0; i < count; ++i) {
        Vector3 direction = Vector3::Zero();
        direction[i % 3] = (i / 3) % 2 ? 1.5 : -0.5;
        rays.push_back(Ray{random.in_box(around), direction});
    }
    return rays;
}

/// Each axis's coordinates of `points`, sorted, without repeats: the planes and lines an axis
/// ray must lie in to run along a mesh's axis-aligned faces and edges.
using AxisCoordinates = std::array<std::vector<double>, 3>;

inline AxisCoordinates axis_coordinates(const std::vector<Eigen::Vector3d>& points) {
    AxisCoordinates values;
    for (const Eigen::Vector3d& p : points) {
        for (int axis = 0; axis < 3; ++axis) values[axis].push_back(p[axis]);
    }
    for (std::vector<double>& axis : values) {
        std::sort(axis.begin(), axis.end());
        axis.erase(std::unique(axis.begin(), axis.end()), axis.end());
    }
    return values;
}

/// Appends `count` rays parallel to the axes (direction exactly +-1 along one), starting a box
/// size beyond `box` and crossing it: a third through random points, a third in a plane through
/// a vertex coordinate (along faces: the rays CGAL's in-plane case answers), a third on a line
/// through two (along edges, through vertices).
inline void append_rays_along_faces_and_edges(Random& random, const Aabb& box,
                                              const AxisCoordinates& coordinates, int count,
                                              std::vector<Ray>& rays) {
    const double size = box.diagonal().norm();
    auto pick = [&](int axis) {
        const std::vector<double>& values = coordinates[static_cast<std::size_t>(axis)];
        return values[static_cast<std::size_t>(
            random.integer(0, static_cast<int>(values.size()) - 1))];
    };
    for (int i = 0; i < count; ++i) {
        const int along = i % 3;
        const double sign = (i / 3) % 2 == 0 ? 1.0 : -1.0;
        Point3 origin = random.in_box(box);
        const int first = (along + 1) % 3, second = (along + 2) % 3;
        if ((i / 6) % 3 != 0) origin[first] = pick(first);
        if ((i / 6) % 3 == 2) origin[second] = pick(second);
        origin[along] = sign > 0 ? box.lower[along] - size : box.upper[along] + size;
        Vector3 direction = Vector3::Zero();
        direction[along] = sign;
        rays.push_back(Ray{origin, direction});
    }
}

}  // namespace csgrt::test
