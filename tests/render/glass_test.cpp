// Glass against closed forms (issue 17, part 3): a ball lens focuses where the lens-maker
// formula says, and rays refracted through CSG solids stay on the side of the surface the
// span lists give them (no leak through a wall, no re-hit of the surface just left).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/scene.h"
#include "csgrt/render/materials.h"
#include "csgrt/render/renderer.h"
#include "csgrt/render/shadow_offset.h"
#include "render/scenes.h"
#include "support/random.h"

namespace csgrt {
namespace {

/// Where a ray parallel to the axis at height h, through a ball of radius R and index n,
/// crosses the axis behind it, as a distance from the centre. The path is symmetric about the
/// ball's centre, so the leaving ray has the same distance h from the centre as the arriving
/// one and is turned by delta = 2 (asin(h / R) - asin(h / (n R))): it meets the axis at
/// h / sin(delta). As h -> 0 this is n R / (2 (n - 1)), the lens-maker focal length of a
/// ball lens measured from its centre (Hecht, "Optics", 5th ed., 6.2).
long double axis_crossing(long double h, long double radius, long double n, long double& delta) {
    delta = 2 * (std::asin(h / radius) - std::asin(h / (n * radius)));
    return h / std::sin(delta);
}

TEST(Glass, ABallLensFocusesAtTheLensMakersFocalLength) {
    const double radius = 1.0;
    const double n = 1.5;
    const double focal = n * radius / (2.0 * (n - 1.0));  // 1.5 from the centre
    const double target_radius = 1e-3;
    // Collimated light: an orthographic camera 0.1 high on the axis, looking through the ball
    // at a small white disk facing it. Without lights the disk is lit from the eye, so a pixel
    // is about T^2 = 0.92 (two Fresnel transmissions) where its ray reaches the disk and 0
    // where it goes on to the black background (internal reflections add at most R = 0.04).
    for (const double offset : {0.0, -0.1, 0.1}) {
        const double target = focal + offset;
        Scene scene;
        Material glass{"glass", Vector3::Zero()};
        glass.ior = n;
        scene.add_object(std::make_shared<Sphere>(Point3(0, 0, 0), radius),
                         scene.add_material(glass));
        scene.add_object(
            std::make_shared<Disk>(Point3(0, 0, -target), Normal3(0, 0, 1), target_radius),
            scene.add_material(Material{"white", Vector3(1, 1, 1)}));
        test::set_orthographic_view(scene, Point3(0, 0, 5), Point3(0, 0, 0), 0.1);
        scene.commit();
        RenderSettings settings = test::settings_of_size(9, 9);
        const Image image = render(scene, settings).image;
        int lit = 0, checked = 0;
        for (int y = 0; y < 9; ++y) {
            for (int x = 0; x < 9; ++x) {
                const long double px = ((x + 0.5L) / 9 - 0.5L) * 0.1L;
                const long double py = (0.5L - (y + 0.5L) / 9) * 0.1L;
                const long double h = std::hypot(px, py);
                // Where the pixel's ray crosses the disk's plane, off the axis: exact for the
                // first pass through the ball (at h = 0.063, the corners, the spherical
                // aberration moves the crossing 0.0017 toward the ball, 7e-5 off the axis at
                // the focus: well inside the disk).
                long double delta = 0;
                const long double miss =
                    h == 0
                        ? 0
                        : std::abs(axis_crossing(h, radius, n, delta) - target) * std::tan(delta);
                // Pixels within 20% of the disk's edge are left out: a ray there may go either way.
                if (std::abs(miss - target_radius) < 0.2 * target_radius) continue;
                ++checked;
                const bool reaches = miss < target_radius;
                const float red = image.at(x, y).red;
                EXPECT_EQ(red > 0.5f, reaches) << "offset " << offset << " pixel " << x << ", " << y
                                               << ": " << red << ", miss " << double(miss);
                lit += red > 0.5f;
            }
        }
        EXPECT_GT(checked, 70);
        // At the focal length every ray reaches the disk; 0.1 before or after it, only the
        // ones near the axis do.
        if (offset == 0.0) {
            EXPECT_EQ(lit, 81);
        } else {
            EXPECT_LT(lit, 40);
            EXPECT_GT(lit, 0);
        }
    }
}

/// Follows rays through a glass solid the way the renderer does (render/src/renderer.cpp,
/// shade_surface): entering or leaving by the sign of the surface's outward normal, refracted
/// by Snell's law or reflected (the choice drawn with the Fresnel weight, so both branches are
/// taken), each new ray from spawn_ray_origin on its own side. Counts the segments whose
/// midpoint is not on the side the path says (a leak through a wall), and the segments shorter
/// than 1e-9 (the surface just left, hit again).
struct LeakCount {
    int segments = 0;
    int wrong_side = 0;
    int rehits = 0;
};

LeakCount follow_rays_through(const std::shared_ptr<const Shape>& solid, std::uint64_t seed) {
    Scene scene;
    scene.add_object(solid);
    scene.commit();
    QueryScratch scratch;
    test::Random random(seed);
    const Aabb box = solid->bounds();
    const double n = 1.5;
    LeakCount count;
    for (int i = 0; i < 300; ++i) {
        Ray ray;
        const Point3 aim = random.in_box(box);
        ray.direction = random.unit_vector();
        ray.origin = aim - 10.0 * ray.direction;
        bool inside = false;
        for (int bounce = 0; bounce < 12; ++bounce) {
            const std::optional<Hit> hit = scene.intersect(ray, scratch);
            if (!hit) break;
            ++count.segments;
            const double length = (hit->point - ray.origin).norm();
            if (length < 1e-9) ++count.rehits;
            const Point3 middle = ray.origin + 0.5 * (hit->point - ray.origin);
            if (length > 1e-6 && solid->contains(middle) != inside) ++count.wrong_side;
            const bool entering = ray.direction.dot(hit->geometric_normal) < 0.0;
            const Normal3 outside_normal =
                entering ? hit->geometric_normal : Normal3(-hit->geometric_normal);
            const double eta = entering ? 1.0 / n : n;
            const double reflectance = fresnel_dielectric(-ray.direction.dot(outside_normal),
                                                          entering ? 1.0 : n, entering ? n : 1.0);
            const std::optional<Vector3> refracted = refract(ray.direction, outside_normal, eta);
            Ray next;
            next.t_max = kInfinity;
            if (refracted && random.uniform() >= reflectance) {
                next.direction = refracted->normalized();
                next.origin = spawn_ray_origin(*hit, -outside_normal);
                inside = entering;
            } else {
                next.direction = reflect(ray.direction, outside_normal);
                next.origin = spawn_ray_origin(*hit, outside_normal);
            }
            ray = next;
        }
    }
    return count;
}

TEST(Glass, RefractionThroughCsgSolidsNeverLeaks) {
    const auto hole = std::make_shared<Instance>(std::make_shared<Cylinder>(0.3, -2.0, 2.0, true),
                                                 Transform::rotate(Vector3(1, 0, 0), kPi / 2));
    const std::vector<std::pair<std::string, std::shared_ptr<const Shape>>> solids = {
        {"lens", make_intersection({std::make_shared<Sphere>(Point3(0, 0, -0.6), 1.0),
                                    std::make_shared<Sphere>(Point3(0, 0, 0.6), 1.0)})},
        {"ball with a hole",
         make_difference(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0), {hole})},
        {"bitten box", make_difference(std::make_shared<Box>(Point3(-1, -1, -1), Point3(1, 1, 1)),
                                       {std::make_shared<Sphere>(Point3(1, 1, 1), 1.0)})},
        {"two overlapping balls", make_union({std::make_shared<Sphere>(Point3(-0.5, 0, 0), 0.6),
                                              std::make_shared<Sphere>(Point3(0.5, 0, 0), 0.6)})},
    };
    std::uint64_t seed = 17;
    for (const auto& [name, solid] : solids) {
        const LeakCount count = follow_rays_through(solid, seed++);
        EXPECT_GT(count.segments, 300) << name;  // rays hit, and bounce inside
        EXPECT_EQ(count.wrong_side, 0) << name << ": of " << count.segments << " segments";
        EXPECT_EQ(count.rehits, 0) << name << ": of " << count.segments << " segments";
    }
}

}  // namespace
}  // namespace csgrt
