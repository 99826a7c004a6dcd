#include "csgrt/render/shadow_offset.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/shapes.h"
#include "support/meshes.h"
#include "support/random.h"

namespace csgrt {
namespace {

using test::direction_around;

constexpr std::array<double, 6> kScales = {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6};

/// The largest coordinate magnitude of a box and a point, as the renderer computes it.
double magnitude_of(const Aabb& box, const Point3& camera) {
    return std::max({box.lower.cwiseAbs().maxCoeff(), box.upper.cwiseAbs().maxCoeff(),
                     camera.cwiseAbs().maxCoeff()});
}

TEST(ShadowOffset, DistanceIsScaledToTheLargestCoordinateWithASceneFloor) {
    // 2^-16 of the largest |coordinate|: exact powers of two make the expected values exact.
    EXPECT_EQ(ray_offset_distance(Point3(3, -1024, 5), 1.0), 1024.0 * 0x1.0p-16);
    EXPECT_EQ(ray_offset_distance(Point3(0.5, 0.25, -0.125), 0.0), 0.5 * 0x1.0p-16);
    // Near the origin the scene's magnitude (times 2^-10) takes over.
    EXPECT_EQ(ray_offset_distance(Point3(0, 0, 0), 4096.0), 4.0 * 0x1.0p-16);
    EXPECT_EQ(ray_offset_distance(Point3(1e-9, 0, 0), -4096.0), 4.0 * 0x1.0p-16);
    const Point3 moved = offset_ray_origin(Point3(8, 0, 0), Normal3(0, 1, 0), 1.0);
    EXPECT_EQ(moved, Point3(8, 8 * 0x1.0p-16, 0));
}

/// One shape at a scale: hits from outside, offset to the side the ray came from, then rays
/// leaving into that side must not hit the (convex) shape again, and rays leaving into the
/// other side must cross the whole solid first.
struct ScaleCase {
    std::shared_ptr<const Shape> shape;
    /// Minimum chord, as a fraction of the scale, for rays entering the solid at cosine >= 0.2
    /// (0: the shape has edges near which a chord may be arbitrarily short).
    double minimum_chord;
};

std::vector<ScaleCase> convex_shapes(double scale) {
    const Vector3 place = scale * Vector3(3.0, -2.0, 5.0);
    auto unit_sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    const Transform ellipsoid = Transform::translate(place) *
                                Transform::rotate(Vector3(1, 2, 3), 0.7) *
                                Transform::scale(scale * Vector3(2.0, 1.0, 0.5));
    const Transform cylinder = Transform::translate(place) *
                               Transform::rotate(Vector3(-2, 1, 0.5), 1.1) *
                               Transform::scale(scale);
    // Chords: a sphere of radius s is crossed in >= 2 s cos = 0.4 s; the ellipsoid's smallest
    // radius of curvature is 0.5^2 / 2 = 0.125 s, so >= 2 * 0.125 * 0.2 = 0.05 s.
    return {
        {std::make_shared<Sphere>(place, scale), 0.3},
        {std::make_shared<Instance>(unit_sphere, ellipsoid), 0.04},
        {std::make_shared<Instance>(std::make_shared<Cylinder>(1.0, -1.0, 1.0, true), cylinder),
         0.0},
    };
}

TEST(ShadowOffset, RaysLeavingAHitNeverHitTheSameSurfaceAtAnyScale) {
    test::Random random(20190226);
    int leaving_rays = 0, entering_rays = 0;
    for (double scale : kScales) {
        for (const ScaleCase& shape_case : convex_shapes(scale)) {
            const Shape& shape = *shape_case.shape;
            const Aabb bounds = shape.bounds();
            const Point3 camera = bounds.center() + 10.0 * scale * random.unit_vector();
            const double scene_magnitude = magnitude_of(bounds, camera);
            int hits = 0;
            for (int trial = 0; trial < 400; ++trial) {
                const Ray camera_ray{camera, random.in_box(bounds) - camera};
                const std::optional<Hit> hit = shape.intersect(camera_ray);
                if (!hit) continue;
                ++hits;
                Normal3 facing = hit->geometric_normal;
                if (facing.dot(camera_ray.direction) > 0.0) facing = -facing;
                const double distance = ray_offset_distance(hit->point, scene_magnitude);
                const Point3 outside = offset_ray_origin(hit->point, facing, scene_magnitude);
                // The move is the stated distance (its rounding is 2^-37 of it) and small: at
                // most 2^-16 of the scene's magnitude.
                ASSERT_NEAR((outside - hit->point).norm(), distance, 1e-9 * distance);
                ASSERT_LE(distance, 0x1.0p-16 * scene_magnitude);
                for (int k = 0; k < 8; ++k) {
                    const Ray leaving{outside, direction_around(random, facing, 0.05)};
                    ++leaving_rays;
                    ASSERT_FALSE(shape.occluded(leaving))
                        << shape.kind() << " at scale " << scale << " re-hit from "
                        << outside.transpose() << " along " << leaving.direction.transpose();
                }
                const Point3 inside = offset_ray_origin(hit->point, -facing, scene_magnitude);
                for (int k = 0; k < 4; ++k) {
                    const Ray entering{inside, direction_around(random, -facing, 0.2)};
                    ++entering_rays;
                    const std::optional<Hit> exit = shape.intersect(entering);
                    ASSERT_TRUE(exit.has_value()) << shape.kind() << " at scale " << scale;
                    const double chord = (exit->point - hit->point).norm();
                    ASSERT_GT(chord, std::max(shape_case.minimum_chord * scale, 2.0 * distance))
                        << shape.kind() << " at scale " << scale << ": exit next to the entry";
                }
            }
            // Rays aim inside the bounds from 10 sizes away: most hit.
            EXPECT_GT(hits, 100) << shape.kind() << " at scale " << scale;
        }
    }
    EXPECT_GT(leaving_rays, 10000);
    EXPECT_GT(entering_rays, 5000);
}

TEST(ShadowOffset, OffsetPointsLieOnTheIntendedSideOfASphereInLongDouble) {
    test::Random random(7);
    for (double scale : kScales) {
        const Point3 centre = scale * Vector3(-4.0, 1.0, 2.0);
        const Sphere sphere(centre, scale);
        const Point3 camera = centre + Vector3(0, 0, 20.0 * scale);
        const double scene_magnitude = magnitude_of(sphere.bounds(), camera);
        for (int trial = 0; trial < 2000; ++trial) {
            const Ray ray{camera, random.in_box(sphere.bounds()) - camera};
            const std::optional<Hit> hit = sphere.intersect(ray);
            if (!hit) continue;
            auto squared_distance = [&](const Point3& p) {
                long double sum = 0.0L;
                for (int axis = 0; axis < 3; ++axis) {
                    const long double d = (long double)p[axis] - (long double)centre[axis];
                    sum += d * d;
                }
                return sum;
            };
            const long double r2 = (long double)scale * (long double)scale;
            const Normal3& n = hit->geometric_normal;
            EXPECT_GT(squared_distance(offset_ray_origin(hit->point, n, scene_magnitude)), r2);
            EXPECT_LT(squared_distance(offset_ray_origin(hit->point, -n, scene_magnitude)), r2);
        }
    }
}

TEST(ShadowOffset, ClearsFloatTrianglesWhoseRayOriginIsRoundedToFloat) {
    // Meshes store float corners and round the ray origin to float, so this is the case the
    // offset's size is set by. The hit point is interpolated from the corners, as Mesh does.
    const test::TestMesh mesh = test::sphere_mesh(3);
    test::Random random(99);
    QueryScratch scratch;
    int checked = 0, self_hits_without_offset = 0;
    for (double scale : kScales) {
        std::vector<Eigen::Vector3d> vertices;
        const Vector3 place = scale * Vector3(3.0, -2.0, 5.0);
        for (const Eigen::Vector3d& v : mesh.vertices) vertices.push_back(place + scale * v);
        const TriangleSet<float> triangles(vertices, mesh.triangles);
        Aabb bounds;
        for (std::size_t i = 0; i < triangles.size(); ++i) bounds.extend(triangles.bounds(i));
        const Point3 camera = place + 10.0 * scale * random.unit_vector();
        const double scene_magnitude = magnitude_of(bounds, camera);
        for (int trial = 0; trial < 300; ++trial) {
            const Ray camera_ray{camera, random.in_box(bounds) - camera};
            const auto prepared = triangles.prepare(camera_ray, scratch);
            HitRecord record;
            bool found = false;
            for (std::size_t i = 0; i < triangles.size(); ++i) {
                HitRecord candidate;
                if (triangles.intersect(i, prepared, candidate) &&
                    (!found || candidate.t < record.t)) {
                    record = candidate;
                    found = true;
                }
            }
            if (!found) continue;
            const std::size_t i = record.primitive;
            const Point3 a = triangles.corner(i, 0).cast<double>();
            const Point3 b = triangles.corner(i, 1).cast<double>();
            const Point3 c = triangles.corner(i, 2).cast<double>();
            const double u = record.u, v = record.v;
            const Point3 p = (1.0 - u - v) * a + u * b + v * c;
            Normal3 facing = (b - a).cross(c - a).normalized();
            if (facing.dot(camera_ray.direction) > 0.0) facing = -facing;
            const Point3 origin = offset_ray_origin(p, facing, scene_magnitude);
            for (int k = 0; k < 8; ++k) {
                const Vector3 direction = direction_around(random, facing, 0.05);
                ++checked;
                ASSERT_FALSE(
                    triangles.occluded(i, triangles.prepare(Ray{origin, direction}, scratch)))
                    << "scale " << scale << " triangle " << i;
                if (triangles.occluded(i, triangles.prepare(Ray{p, direction}, scratch))) {
                    ++self_hits_without_offset;
                }
            }
        }
    }
    EXPECT_GT(checked, 10000);
    // The check has teeth: without the offset, rays re-hit the triangle they leave.
    EXPECT_GT(self_hits_without_offset, checked / 20);
}

}  // namespace
}  // namespace csgrt
