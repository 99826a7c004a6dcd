// Secondary rays leaving a hit point (toward a light, along the mirror reflection, and into a
// solid) never find the surface they leave through rounding error, at scene scales from 1e-4
// to 1e6, for analytic shapes, instances, CSG and float and double meshes. The origin is moved
// off the surface by the renderer's own rule, spawn_ray_origin (render/shadow_offset.h): by the
// hit's point error, a few double ulps of its coordinates for analytic shapes and CSG and the
// float margin of Waechter and Binder (Ray Tracing Gems, 2019, ch. 6) for float triangles,
// carried through instances (pbrt-v4's error bounds).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/mesh/mesh.h"
#include "csgrt/render/shadow_offset.h"
#include "stress/stress_config.h"
#include "stress/summary.h"
#include "support/meshes.h"
#include "support/placed_mesh.h"
#include "support/random.h"

namespace csgrt {
namespace {

using test::mesh_at;

struct Subject {
    std::string name;
    std::shared_ptr<const Shape> shape;
    /// Convex solid or flat surface: a ray leaving on the side it arrived from never meets it
    /// again, and a ray entering a convex solid crosses at least `minimum_chord` (in sizes,
    /// for rays at |cos| >= 0.2 to the normal) before it leaves.
    bool convex = false;
    double minimum_chord = 0.0;
};

std::vector<Subject> subjects(double scale) {
    const Vector3 place = scale * Vector3(3.0, -2.0, 5.0);
    const Transform placement = Transform::translate(place) *
                                Transform::rotate(Vector3(1, 2, 3), 0.7) * Transform::scale(scale);
    const Transform stretched = placement * Transform::scale(Vector3(2.0, 1.0, 0.5));
    auto unit_sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    auto instance = [&](std::shared_ptr<const Shape> shape, const Transform& transform) {
        return std::make_shared<Instance>(std::move(shape), transform);
    };
    std::vector<Subject> list;
    // Chords at |cos| >= 0.2: a sphere of radius 1 is crossed in >= 2 cos = 0.4; the ellipsoid
    // (radii 2, 1, 0.5) has a smallest radius of curvature of 0.5^2 / 2 = 0.125, so >= 0.05.
    list.push_back({"sphere", std::make_shared<Sphere>(place, scale), true, 0.4});
    list.push_back({"ellipsoid (instance)", instance(unit_sphere, stretched), true, 0.05});
    list.push_back({"box",
                    std::make_shared<Box>(place - scale * Vector3(1, 0.5, 0.75),
                                          place + scale * Vector3(1, 0.5, 0.75)),
                    true, 0.0});
    list.push_back({"cylinder (capped, instance)",
                    instance(std::make_shared<Cylinder>(1.0, -1.0, 1.0, true), placement), true,
                    0.0});
    list.push_back({"cone (capped, instance)",
                    instance(std::make_shared<Cone>(1.0, 0.0, 2.0, true), placement), true, 0.0});
    list.push_back({"plane", std::make_shared<Plane>(place, Normal3(1, 2, 3)), true, 0.0});
    list.push_back({"disk", std::make_shared<Disk>(place, Normal3(-1, 2, 0.5), scale), true, 0.0});
    list.push_back({"triangle",
                    std::make_shared<Triangle>(place + scale * Vector3(-1, -0.5, 0.2),
                                               place + scale * Vector3(1, -0.3, -0.1),
                                               place + scale * Vector3(0.1, 1, 0.3)),
                    true, 0.0});
    list.push_back({"rectangle (instance)",
                    instance(std::make_shared<Rectangle>(Point3(-1, 0, -1), Vector3(2, 0, 0),
                                                         Vector3(0, 0, 2)),
                             placement),
                    true, 0.0});
    list.push_back(
        {"torus (instance)", instance(std::make_shared<Torus>(1.0, 0.25), placement), false, 0.0});
    list.push_back({"part_sphere", std::make_shared<PartSphere>(place, scale, 1.0, 5.0, 0.5, 2.5),
                    false, 0.0});
    list.push_back({"part_torus (instance)",
                    instance(std::make_shared<PartTorus>(1.0, 0.25, 1.0, 5.0, 4.0, 8.0), placement),
                    false, 0.0});
    list.push_back(
        {"box - sphere (csg)",
         std::make_shared<Boolean>(
             BooleanOperation::Difference,
             instance(std::make_shared<Box>(Point3(-1, -1, -1), Point3(1, 1, 1)), placement),
             instance(unit_sphere,
                      placement * Transform::translate(Vector3(1, 1, 0)) * Transform::scale(0.8))),
         false, 0.0});
    for (const bool double_precision : {false, true}) {
        const std::string precision = double_precision ? " double" : " float";
        // Convex, but a chord of a polyhedron has no simple lower bound: entering rays are
        // checked for self hits only.
        list.push_back({"sphere_mesh(4)" + precision,
                        mesh_at(test::sphere_mesh(4), placement, double_precision), true, 0.0});
        list.push_back(
            {"integer_cube(4)" + precision,
             mesh_at(test::integer_cube(4),
                     placement * Transform::scale(0.5) * Transform::translate(Vector3(-2, -2, -2)),
                     double_precision),
             true, 0.0});
    }
    return list;
}

/// Which surface a hit is: the leaf and its primitive.
bool same_surface(const Hit& a, const Hit& b) {
    return a.shape == b.shape && a.primitive_id == b.primitive_id;
}

struct Tally {
    long primaries = 0;
    long leaving = 0;
    long entering = 0;
    long self_hits = 0;
};

TEST(SelfIntersection, SecondaryRaysNeverRehitTheSurfaceTheyLeave) {
    const int primaries = 1500 * test::stress_multiplier();
    test::Random random(20190226);
    std::printf(
        "\n  | shape | primary hits | leaving rays (light, mirror) | entering rays |"
        " self hits |\n");
    std::map<std::string, Tally> tallies;
    std::vector<std::string> order;
    for (const double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6}) {
        for (const Subject& subject : subjects(scale)) {
            if (!tallies.count(subject.name)) order.push_back(subject.name);
            Tally& tally = tallies[subject.name];
            const Shape& shape = *subject.shape;
            const Point3 center = scale * Vector3(3.0, -2.0, 5.0);
            const Aabb box = shape.bounds().is_finite() ? shape.bounds()
                                                        : Aabb(center - Vector3::Constant(scale),
                                                               center + Vector3::Constant(scale));
            const Point3 camera = center + 6.0 * scale * Vector3(0.3, 0.5, -0.8);
            for (int i = 0; i < primaries; ++i) {
                // Primary rays from around the camera toward the object.
                const Point3 origin = camera + scale * random.unit_vector();
                const Ray primary{origin,
                                  (random.in_box(box) - origin) * random.uniform(0.25, 4.0)};
                const std::optional<Hit> hit = shape.intersect(primary);
                if (!hit) continue;
                ++tally.primaries;
                // The side the primary ray arrived from, and the offset origins on either side.
                const Normal3 toward = primary.direction.dot(hit->geometric_normal) < 0.0
                                           ? hit->geometric_normal
                                           : Normal3(-hit->geometric_normal);
                const double offset = spawn_offset_distance(*hit, toward);
                const Point3 outside = spawn_ray_origin(*hit, toward);
                const Point3 inside = spawn_ray_origin(*hit, -toward);
                // A hit on the surface left that is due to rounding lies where the ray meets
                // that surface point again: the origin is `offset` (give or take rounding,
                // far smaller) off it along the normal, so at most 2 offset / |cos| along the
                // ray. Farther hits on the same surface are real (a cone near its apex).
                auto self_hit_reach = [&](const Ray& ray, const Normal3& normal) {
                    return 2.0 * offset * ray.direction.norm() /
                           std::abs(ray.direction.dot(normal));
                };
                auto expect_no_self_hit = [&](const Ray& ray, const char* what) {
                    const std::optional<Hit> again = shape.intersect(ray);
                    if (!again) return;
                    const double distance = again->t * ray.direction.norm();
                    const bool self =
                        same_surface(*again, *hit) && distance < self_hit_reach(ray, toward);
                    const bool forbidden = subject.convex || self;
                    if (forbidden) {
                        ++tally.self_hits;
                        ADD_FAILURE() << subject.name << " at scale " << scale << ": " << what
                                      << " ray re-hits at distance " << distance << " (offset "
                                      << offset << ")";
                    }
                };
                // Toward a light in the hemisphere the primary ray came from.
                Vector3 light = random.unit_vector();
                if (light.dot(toward) < 0.0) light = -light;
                if (light.dot(toward) >= 0.05) {
                    ++tally.leaving;
                    expect_no_self_hit(Ray{outside, light * random.uniform(0.25, 4.0)}, "light");
                }
                // The mirror reflection.
                const Vector3 d = primary.direction.normalized();
                const Vector3 mirror = d - 2.0 * d.dot(toward) * toward;
                if (mirror.dot(toward) >= 0.05) {
                    ++tally.leaving;
                    expect_no_self_hit(Ray{outside, mirror}, "mirror");
                }
                // Into a solid: the first hit is the far side, never the surface just entered.
                if (shape.is_solid() && d.dot(-toward) >= 0.2) {
                    ++tally.entering;
                    const std::optional<Hit> exit = shape.intersect(Ray{inside, d});
                    const double chord = exit ? exit->t : kInfinity;
                    const bool self = exit && same_surface(*exit, *hit) &&
                                      chord < self_hit_reach(Ray{inside, d}, toward);
                    const bool too_short =
                        subject.minimum_chord > 0.0 && chord < subject.minimum_chord * scale;
                    if (self || too_short || !exit) {
                        ++tally.self_hits;
                        ADD_FAILURE() << subject.name << " at scale " << scale
                                      << ": entering ray finds " << (exit ? "a hit" : "nothing")
                                      << " at distance " << chord << " (offset " << offset << ")";
                    }
                }
            }
        }
    }
    for (const std::string& name : order) {
        const Tally& t = tallies[name];
        std::printf("  | %s | %ld | %ld | %ld | %ld |\n", name.c_str(), t.primaries, t.leaving,
                    t.entering, t.self_hits);
        EXPECT_EQ(t.self_hits, 0) << name;
        test::summarize(name, t.leaving + t.entering, t.self_hits);
        EXPECT_GT(t.primaries, primaries / 2) << name;  // of 6 x primaries aimed at the bounds
    }
}

}  // namespace
}  // namespace csgrt
