// Secondary rays spawned by the renderer's rule (spawn_ray_origin: the hit's own point error,
// render/shadow_offset.h) against three independent answers: "a ray leaving a surface never
// meets it again" on every kind of shape at every distance from the origin; the same lit and
// shadowed pixels wherever the scene is placed; and a long-double reference for grazing light
// in a concave CSG cavity.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/camera.h"
#include "csgrt/csg/scene.h"
#include "csgrt/mesh/mesh.h"
#include "csgrt/render/renderer.h"
#include "csgrt/render/shadow_offset.h"
#include "render/scenes.h"
#include "support/meshes.h"
#include "support/placed_mesh.h"
#include "support/random.h"

namespace csgrt {
namespace {

using test::direction_around;
using test::mesh_at;

constexpr std::array<double, 4> kTranslations = {0.0, 1e2, 1e4, 1e6};

/// The direction in which every test scene is moved away from the origin (not along an axis,
/// so every coordinate grows).
const Vector3 kShiftDirection = Vector3(0.6, -0.48, 0.64);

struct Subject {
    std::string name;
    std::shared_ptr<const Shape> shape;
    /// Convex solid or flat surface: a ray leaving on the side it arrived from never meets it
    /// again. Otherwise only a re-hit of the same primitive next to the start is forbidden.
    bool convex = false;
};

/// Every kind of leaf, instances with rotation, non-uniform scale and shear, CSG, and meshes
/// (float and double, placed in world space and under an instance), around `place` with size
/// `size`.
std::vector<Subject> subjects(const Point3& place, double size) {
    const Transform placement = Transform::translate(place) *
                                Transform::rotate(Vector3(1, 2, 3), 0.7) * Transform::scale(size);
    Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
    shear(0, 1) = 0.6;
    shear(2, 0) = -0.3;
    const Transform sheared =
        placement * Transform(shear, Vector3::Zero()) * Transform::scale(Vector3(2.0, 1.0, 0.5));
    auto unit_sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    auto instance = [](std::shared_ptr<const Shape> shape, const Transform& transform) {
        return std::make_shared<Instance>(std::move(shape), transform);
    };
    std::vector<Subject> list;
    list.push_back({"sphere", std::make_shared<Sphere>(place, size), true});
    list.push_back({"sheared ellipsoid (instance)", instance(unit_sphere, sheared), true});
    list.push_back({"box",
                    std::make_shared<Box>(place - size * Vector3(1, 0.5, 0.75),
                                          place + size * Vector3(1, 0.5, 0.75)),
                    true});
    list.push_back({"cylinder (instance)",
                    instance(std::make_shared<Cylinder>(1.0, -1.0, 1.0, true), placement), true});
    list.push_back({"cone (instance)",
                    instance(std::make_shared<Cone>(1.0, 0.0, 2.0, true), placement), true});
    list.push_back({"plane", std::make_shared<Plane>(place, Normal3(1, 2, 3).normalized()), true});
    list.push_back(
        {"disk", std::make_shared<Disk>(place, Normal3(-1, 2, 0.5).normalized(), size), true});
    list.push_back({"triangle",
                    std::make_shared<Triangle>(place + size * Vector3(-1, -0.5, 0.2),
                                               place + size * Vector3(1, -0.3, -0.1),
                                               place + size * Vector3(0.1, 1, 0.3)),
                    true});
    list.push_back(
        {"torus (instance)", instance(std::make_shared<Torus>(1.0, 0.25), placement), false});
    list.push_back(
        {"part_sphere", std::make_shared<PartSphere>(place, size, 1.0, 5.0, 0.5, 2.5), false});
    list.push_back({"part_cylinder (instance)",
                    instance(std::make_shared<PartCylinder>(1.0, -1.0, 1.0, 0.5, 4.0), placement),
                    false});
    auto box =
        std::make_shared<Box>(place - size * Vector3(1, 1, 1), place + size * Vector3(1, 1, 1));
    auto bite = std::make_shared<Sphere>(place + size * Vector3(1, 1, 1), size);
    list.push_back({"box - sphere (CSG)", make_difference(box, {bite}), false});
    for (const bool double_precision : {false, true}) {
        const std::string precision = double_precision ? " double" : " float";
        list.push_back({"sphere_mesh(3)" + precision,
                        mesh_at(test::sphere_mesh(3), placement, double_precision), true});
        list.push_back(
            {"sphere_mesh(3)" + precision + " (instance)",
             instance(mesh_at(test::sphere_mesh(3), Transform(), double_precision), sheared),
             true});
    }
    return list;
}

TEST(SecondaryRays, NeverRehitTheSurfaceTheyLeaveWhereverTheSceneIs) {
    // Rays leave at cosines down to 0.02 with the normal. Besides the rule itself (factor 1),
    // the point error is shrunk by powers of two to show how much of it is margin: the table
    // prints the self hits at each fraction.
    constexpr int kFractions = 10;
    std::array<long, kFractions> self_hits{};
    long leaving_rays = 0;
    test::Random random(20190226);
    std::printf("\n  | translation | size | rays leaving | self hits at point error x 1 |\n");
    for (const double translation : kTranslations) {
        for (const double size : {1e-2, 1.0}) {
            const Point3 place = translation * kShiftDirection;
            long rays_here = 0, hits_here = 0;
            for (const Subject& subject : subjects(place, size)) {
                const Shape& shape = *subject.shape;
                const Aabb box = shape.bounds().is_finite() ? shape.bounds()
                                                            : Aabb(place - Vector3::Constant(size),
                                                                   place + Vector3::Constant(size));
                const Point3 camera = place + 6.0 * size * Vector3(0.3, 0.5, -0.8);
                for (int i = 0; i < 150; ++i) {
                    const Ray primary{camera, random.in_box(box) - camera};
                    const std::optional<Hit> hit = shape.intersect(primary);
                    if (!hit) continue;
                    const Normal3 toward = primary.direction.dot(hit->geometric_normal) < 0.0
                                               ? hit->geometric_normal
                                               : Normal3(-hit->geometric_normal);
                    for (int k = 0; k < 6; ++k) {
                        const Vector3 direction = direction_around(random, toward, 0.02);
                        ++leaving_rays;
                        ++rays_here;
                        for (int f = 0; f < kFractions; ++f) {
                            Hit shrunk = *hit;
                            shrunk.point_error = std::ldexp(hit->point_error, -f);
                            const Ray leaving{spawn_ray_origin(shrunk, toward), direction};
                            const std::optional<Hit> again = shape.intersect(leaving);
                            if (!again) continue;
                            // A self hit is the same primitive met again within a few offsets
                            // of the start; farther ones are real (a torus seen across).
                            const double reach = 4.0 * spawn_offset_distance(*hit, toward) /
                                                 std::abs(direction.normalized().dot(toward));
                            const bool self = again->shape == hit->shape &&
                                              again->primitive_id == hit->primitive_id &&
                                              again->t * direction.norm() < reach;
                            if (!(subject.convex || self)) continue;
                            ++self_hits[f];
                            if (f == 0) {
                                ++hits_here;
                                ADD_FAILURE()
                                    << subject.name << " at " << translation << ", size " << size
                                    << ": re-hit at distance " << again->t * direction.norm()
                                    << " (error " << hit->point_error << ")";
                            }
                        }
                    }
                }
            }
            std::printf("  | %g | %g | %ld | %ld |\n", translation, size, rays_here, hits_here);
        }
    }
    std::printf("\n  | point error x | self hits (of %ld rays) |\n", leaving_rays);
    for (int f = 0; f < kFractions; ++f) std::printf("  | 2^-%d | %ld |\n", f, self_hits[f]);
    EXPECT_EQ(self_hits[0], 0);
    EXPECT_GT(leaving_rays, 20000);
}

/// The largest coordinate magnitude of the scene's bounds and camera: what the renderer's
/// former offset (offset_ray_origin, 2^-16 of it near the origin) was sized by.
double scene_magnitude(const Scene& scene) {
    double magnitude = scene.camera().position.cwiseAbs().maxCoeff();
    const Aabb& bounds = scene.bounds();
    if (!bounds.is_empty() && bounds.is_finite()) {
        magnitude = std::max(
            {magnitude, bounds.lower.cwiseAbs().maxCoeff(), bounds.upper.cwiseAbs().maxCoeff()});
    }
    return magnitude;
}

/// Whether the hit `ray` finds in `scene` is lit by the scene's one point light, with the
/// renderer's former shadow offset: the "before" column of the tables.
std::optional<bool> lit_with_former_offset(const Scene& scene, const Ray& ray) {
    const std::optional<Hit> hit = scene.intersect(ray, thread_query_scratch());
    if (!hit) return std::nullopt;
    Normal3 n = hit->geometric_normal;
    if (n.dot(ray.direction) > 0.0) n = -n;
    const auto& light = std::get<PointLight>(scene.lights().front());
    if (!(n.dot(light.position - hit->point) > 0.0)) return false;
    const Point3 origin = offset_ray_origin(hit->point, n, scene_magnitude(scene));
    Ray shadow{origin, light.position - origin};
    shadow.t_max = 1.0 - kRayOffsetRelative;
    return !scene.occluded(shadow, thread_query_scratch());
}

/// Thin gaps over a floor: a disk 0.05 above it, a sphere 0.01 above it, a block 0.002 above
/// it (a quarter high, so that its shadow reaches out from under it where the camera sees it),
/// lit by one point light, everything moved by `shift`.
Scene thin_gaps(const Vector3& shift) {
    Scene scene;
    scene.add_object(std::make_shared<Box>(shift + Vector3(-4, -1, -4), shift + Vector3(4, 0, 4)),
                     0, "floor");
    scene.add_object(
        std::make_shared<Disk>(shift + Vector3(-1.2, 0.05, 0.3), Normal3(0, 1, 0), 0.6), 0,
        "disk 0.05 above");
    scene.add_object(std::make_shared<Sphere>(shift + Vector3(0.6, 0.51, -0.4), 0.5), 0,
                     "sphere 0.01 above");
    scene.add_object(
        std::make_shared<Box>(shift + Vector3(0.4, 0.002, 0.8), shift + Vector3(1.6, 0.252, 1.6)),
        0, "block 0.002 above");
    // Low, so that shadows reach out from under their casters where the camera sees them.
    scene.add_light(PointLight{shift + Vector3(5.0, 1.5, 2.0), Vector3(100, 100, 100)});
    test::set_view(scene, shift + Vector3(0.0, 3.0, 6.0), shift + Vector3(0.0, 0.0, 0.0), 45.0);
    scene.commit();
    return scene;
}

TEST(SecondaryRays, AMovedSceneShadowsTheSamePixelsAndKeepsItsThinGaps) {
    RenderSettings settings = test::settings_of_size(64, 48);
    settings.threads = 1;
    const Scene at_origin = thin_gaps(Vector3::Zero());
    const RenderResult reference = render(at_origin, settings);
    long shadowed_floor = 0;
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            const Pixel& p = reference.image.at(x, y);
            if (p.object_id == 0 && p.alpha > 0.0f && p.red == 0.0f) ++shadowed_floor;
        }
    }
    // The three thin objects cast shadows on the floor at the origin (independently of any
    // offset: 0.002 is 10^9 of the point error there).
    ASSERT_GT(shadowed_floor, 100);
    // Each of them: the first object a dark floor pixel's shadow ray meets. Moved scenes must
    // shadow the same pixels (below), so each keeps its shadow at every translation.
    std::array<long, 4> shadowed_by{};
    const CameraFilm origin_film(at_origin.camera(), double(settings.width) / settings.height);
    const Point3 light = std::get<PointLight>(at_origin.lights().front()).position;
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            const Pixel& p = reference.image.at(x, y);
            if (!(p.object_id == 0 && p.alpha > 0.0f && p.red == 0.0f)) continue;
            const Ray ray =
                origin_film.ray((x + 0.5) / settings.width, (y + 0.5) / settings.height);
            const std::optional<Hit> floor = at_origin.intersect(ray, thread_query_scratch());
            ASSERT_TRUE(floor.has_value());
            const Point3 origin = spawn_ray_origin(*floor, Normal3(0, 1, 0));
            Ray shadow{origin, light - origin};
            shadow.t_max = 1.0;
            const std::optional<Hit> caster = at_origin.intersect(shadow, thread_query_scratch());
            if (caster && caster->object_id < shadowed_by.size()) ++shadowed_by[caster->object_id];
        }
    }
    std::printf("\n  dark floor pixels at the origin: %ld (disk %ld, sphere %ld, block %ld)\n",
                shadowed_floor, shadowed_by[1], shadowed_by[2], shadowed_by[3]);
    for (std::size_t caster = 1; caster < shadowed_by.size(); ++caster)
        EXPECT_GT(shadowed_by[caster], 5) << "caster " << caster;
    std::printf(
        "\n  | translation | pixels whose lit/shadowed state differs from the origin's:"
        " former offset | point-error offset (renderer) |\n");
    for (const double translation : kTranslations) {
        const Scene moved = thin_gaps(translation * kShiftDirection);
        const RenderResult result = render(moved, settings);
        const CameraFilm film(moved.camera(), double(settings.width) / settings.height);
        long differing = 0, differing_before = 0;
        for (int y = 0; y < settings.height; ++y) {
            for (int x = 0; x < settings.width; ++x) {
                const Pixel& expected = reference.image.at(x, y);
                const Pixel& got = result.image.at(x, y);
                ASSERT_EQ(got.object_id, expected.object_id) << x << ", " << y;
                const bool lit = expected.red > 0.0f;
                if ((got.red > 0.0f) != lit) ++differing;
                const std::optional<bool> before = lit_with_former_offset(
                    moved, film.ray((x + 0.5) / settings.width, (y + 0.5) / settings.height));
                if (before.has_value() && *before != lit) ++differing_before;
            }
        }
        std::printf("  | %g | %ld | %ld |\n", translation, differing_before, differing);
        EXPECT_EQ(differing, 0) << "translation " << translation;
    }
}

/// The long-double interval of a line o + t d inside an axis-aligned box (empty: lo >= hi),
/// the faces where it enters and leaves, and the next-latest entry and next-earliest exit (the
/// line passes near an edge of the box where one of them nearly ties).
struct BoxCrossing {
    long double lo = -1e4000L, hi = 1e4000L;
    int entry_axis = -1, exit_axis = -1;
    long double second_entry = -1e4000L, second_exit = 1e4000L;
};

using Vec3L = Eigen::Matrix<long double, 3, 1>;

BoxCrossing cross_box(const Vec3L& o, const Vec3L& d, const Vec3L& lower, const Vec3L& upper) {
    BoxCrossing c;
    for (int axis = 0; axis < 3; ++axis) {
        if (d[axis] == 0.0L) {
            if (o[axis] < lower[axis] || o[axis] > upper[axis]) c.lo = 1e4000L;
            continue;
        }
        long double t0 = (lower[axis] - o[axis]) / d[axis];
        long double t1 = (upper[axis] - o[axis]) / d[axis];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > c.lo) {
            c.second_entry = c.lo;
            c.lo = t0;
            c.entry_axis = axis;
        } else {
            c.second_entry = std::max(c.second_entry, t0);
        }
        if (t1 < c.hi) {
            c.second_exit = c.hi;
            c.hi = t1;
            c.exit_axis = axis;
        } else {
            c.second_exit = std::min(c.second_exit, t1);
        }
    }
    return c;
}

/// A cavity scene: a block with a cavity cut into its top face (a ball, a spherical dish, or a
/// box, a flat-floored pocket), a point light just above the top face so that light grazes the
/// cavity and the rim shadows part of it, and a camera looking into it.
struct Cavity {
    const char* name;
    Vec3L lower{-2.0L, -1.0L, -2.0L}, upper{2.0L, 0.0L, 2.0L};
    /// The cut: a ball (radius > 0) or else the box [cut_lower, cut_upper].
    Vec3L centre{0.0L, 0.0L, 0.0L};
    long double radius = 0.0L;
    Vec3L cut_lower{0.0L, 0.0L, 0.0L}, cut_upper{0.0L, 0.0L, 0.0L};
    Point3 light{0.0, 0.0, 0.0};
    Point3 eye{0.0, 0.0, 0.0}, look_at{0.0, 0.0, 0.0};
    double fov_degrees = 50.0;

    std::shared_ptr<const Shape> shape(const Vector3& shift) const {
        auto block =
            std::make_shared<Box>(shift + lower.cast<double>(), shift + upper.cast<double>());
        std::shared_ptr<const Shape> cut;
        if (radius > 0.0L) {
            cut = std::make_shared<Sphere>(shift + centre.cast<double>(), double(radius));
        } else {
            cut = std::make_shared<Box>(shift + cut_lower.cast<double>(),
                                        shift + cut_upper.cast<double>());
        }
        return make_difference(block, {cut});
    }

    /// The intervals of the line o + t d inside the block minus the cut, at most two, and the
    /// events near which the double computation may decide either way.
    struct Along {
        std::vector<std::array<long double, 2>> inside;
        std::vector<long double> events;
    };
    Along along(const Vec3L& o, const Vec3L& d) const {
        Along result;
        const BoxCrossing block = cross_box(o, d, lower, upper);
        if (!(block.lo < block.hi)) return result;
        result.events = {block.lo, block.hi, block.second_entry, block.second_exit};
        long double t0 = 0.0L, t1 = 0.0L;
        bool cut = false;
        if (radius > 0.0L) {
            const Vec3L f = o - centre;
            const long double a = d.squaredNorm(), b = f.dot(d);
            const long double disc = b * b - a * (f.squaredNorm() - radius * radius);
            if (disc > 0.0L) {
                const long double root = std::sqrt(disc);
                t0 = (-b - root) / a;
                t1 = (-b + root) / a;
                cut = true;
                result.events.insert(result.events.end(), {t0, t1});
            }
        } else {
            const BoxCrossing box = cross_box(o, d, cut_lower, cut_upper);
            if (box.lo < box.hi) {
                t0 = box.lo;
                t1 = box.hi;
                cut = true;
                result.events.insert(result.events.end(),
                                     {box.lo, box.hi, box.second_entry, box.second_exit});
            }
        }
        if (!cut) {
            result.inside.push_back({block.lo, block.hi});
            return result;
        }
        if (block.lo < std::min(t0, block.hi))
            result.inside.push_back({block.lo, std::min(t0, block.hi)});
        if (std::max(t1, block.lo) < block.hi)
            result.inside.push_back({std::max(t1, block.lo), block.hi});
        return result;
    }

    /// The normal facing the air at the first hit t of the line o + t d.
    Vec3L normal(const Vec3L& o, const Vec3L& d, long double t) const {
        const BoxCrossing block = cross_box(o, d, lower, upper);
        Vec3L n = Vec3L::Zero();
        if (t == block.lo) {
            n[block.entry_axis] = d[block.entry_axis] > 0.0L ? -1.0L : 1.0L;
        } else if (radius > 0.0L) {
            n = (centre - (o + t * d)) / radius;  // the dish faces into the ball
        } else {
            // The cut box's face where the line leaves it: it faces back into the pocket.
            const BoxCrossing box = cross_box(o, d, cut_lower, cut_upper);
            n[box.exit_axis] = d[box.exit_axis] > 0.0L ? -1.0L : 1.0L;
        }
        return n;
    }
};

enum class Verdict { kMiss, kLit, kDark, kAmbiguous };

/// The exact (long double) answer for a camera ray: its hit on the cavity solid and whether the
/// light reaches it. kAmbiguous within `band` (relative) of an edge, a tangent or a shadow edge.
Verdict reference_verdict(const Cavity& cavity, const Ray& ray) {
    constexpr long double band = 1e-9L;
    const Vec3L o = ray.origin.cast<long double>(), d = ray.direction.cast<long double>();
    const Cavity::Along primary = cavity.along(o, d);
    if (primary.inside.empty()) return Verdict::kMiss;
    const long double t = primary.inside.front()[0];
    if (!(t > 0.0L)) return Verdict::kMiss;
    for (long double event : primary.events) {
        if (event != t && std::abs(event - t) < band * (1.0L + std::abs(t))) {
            return Verdict::kAmbiguous;
        }
    }
    const Vec3L p = o + t * d;
    const Vec3L n = cavity.normal(o, d, t);
    const Vec3L l = cavity.light.cast<long double>() - p;
    const long double cosine = n.dot(l) / l.norm();
    if (std::abs(cosine) < band) return Verdict::kAmbiguous;
    if (cosine < 0.0L) return Verdict::kDark;
    const Cavity::Along shadow = cavity.along(p, l);
    Verdict verdict = Verdict::kLit;
    for (const auto& [start, end] : shadow.inside) {
        if (std::abs(end) < band) continue;  // the surface the point is on, behind it
        const long double overlap = std::min(end, 1.0L) - std::max(start, 0.0L);
        if (std::abs(overlap) < band || end - start < band) return Verdict::kAmbiguous;
        if (overlap > 0.0L) verdict = Verdict::kDark;
    }
    return verdict;
}

/// The cavities. The dish: a ball cut from the block, the light 0.05 above the rim, seen
/// whole. The same dish with the light just inside the tangent plane of its near rim
/// (0.40 high at x = -1.3, where the plane is 0.456 high), seen closely where the rim's shadow
/// ends on the near wall: the light grazes the concave wall there. The pocket: a box 0.02 deep,
/// the light 0.0025 above the top face 0.3 beyond the rim, so that the rim's shadow falls on
/// the floor at x = 0.9, where the light rises 1/120 above the floor. Grazing light multiplies
/// a shadow ray's offset along the normal: leaving a distance e above the floor, it clears the
/// rim as if the rim were 120 e further away, so the former offset (2^-16 of the point's largest
/// coordinate, 1.5e-5 here) moves the shadow's edge by 1.8e-3, about a pixel of the camera
/// looking at that edge. Near the origin; only the offset decides.
std::vector<Cavity> cavities() {
    Cavity dish{"dish"};
    dish.centre = Vec3L(0.0L, 0.5L, 0.0L);
    dish.radius = 1.2L;
    dish.light = Point3(-1.3, 0.05, 0.1);
    dish.eye = Point3(0.9, 3.0, 1.6);
    dish.look_at = Point3(-0.2, -0.3, 0.0);
    dish.fov_degrees = 50.0;
    Cavity wall = dish;
    wall.name = "dish, light grazing its near wall";
    wall.light = Point3(-1.3, 0.40, 0.1);
    wall.eye = Point3(0.6, 1.5, 0.3);
    wall.look_at = Point3(-1.02, -0.12, 0.0);
    wall.fov_degrees = 2.0;
    Cavity pocket{"pocket"};
    pocket.cut_lower = Vec3L(-1.5L, -0.02L, -1.5L);
    pocket.cut_upper = Vec3L(1.5L, 1.0L, 1.5L);
    pocket.light = Point3(-1.8, 0.0025, 0.2);
    // Above the shadow's edge, off its line, so the edge crosses the image diagonally.
    pocket.look_at = Point3(0.9, -0.02, 1.0);
    pocket.eye = pocket.look_at + Vector3(0.35, 0.5, 0.25);
    pocket.fov_degrees = 8.0;
    return {dish, wall, pocket};
}

TEST(SecondaryRays, GrazingLightInConcaveCavitiesMatchesALongDoubleReference) {
    RenderSettings settings = test::settings_of_size(48, 48);
    settings.threads = 1;
    std::printf(
        "\n  | cavity | translation | pixels | lit | dark | ambiguous (within 1e-9) |"
        " disagreements: former offset | point-error offset (renderer) |\n");
    for (const Cavity& cavity : cavities()) {
        for (const double translation : {0.0, 1e4}) {
            // The reference is computed for the scene at the origin with the moved scene's rays
            // moved back: the same geometry, exactly.
            const Vector3 shift = translation * kShiftDirection;
            Scene scene;
            scene.add_object(cavity.shape(shift), 0, cavity.name);
            scene.add_light(PointLight{shift + cavity.light, Vector3(10, 10, 10)});
            test::set_view(scene, shift + cavity.eye, shift + cavity.look_at, cavity.fov_degrees);
            scene.commit();
            const RenderResult result = render(scene, settings);
            const CameraFilm film(scene.camera(), 1.0);
            long lit = 0, dark = 0, ambiguous = 0, wrong = 0, wrong_before = 0;
            for (int y = 0; y < settings.height; ++y) {
                for (int x = 0; x < settings.width; ++x) {
                    const Ray ray =
                        film.ray((x + 0.5) / settings.width, (y + 0.5) / settings.height);
                    // Moving the origin back by `shift` rounds it; at 10^4 that is 2^-40 and
                    // far inside the ambiguity band.
                    const Ray at_origin{ray.origin - shift, ray.direction};
                    const Verdict verdict = reference_verdict(cavity, at_origin);
                    const Pixel& pixel = result.image.at(x, y);
                    if (verdict == Verdict::kAmbiguous) {
                        ++ambiguous;
                        continue;
                    }
                    ASSERT_EQ(pixel.alpha > 0.0f, verdict != Verdict::kMiss)
                        << cavity.name << " " << x << ", " << y;
                    if (verdict == Verdict::kMiss) continue;
                    const bool expected_lit = verdict == Verdict::kLit;
                    (expected_lit ? lit : dark) += 1;
                    if ((pixel.red > 0.0f) != expected_lit) {
                        ++wrong;
                        ADD_FAILURE()
                            << cavity.name << " pixel " << x << ", " << y << " at translation "
                            << translation << ": expected " << (expected_lit ? "lit" : "dark");
                    }
                    const std::optional<bool> before = lit_with_former_offset(scene, ray);
                    if (before.has_value() && *before != expected_lit) ++wrong_before;
                }
            }
            std::printf("  | %s | %g | %d | %ld | %ld | %ld | %ld | %ld |\n", cavity.name,
                        translation, settings.width * settings.height, lit, dark, ambiguous,
                        wrong_before, wrong);
            // Light must graze: both verdicts occur in the cavity.
            EXPECT_GT(lit, 200) << cavity.name;
            EXPECT_GT(dark, 100) << cavity.name;
            // The control: with grazing light the former offset gets shadow edges wrong even
            // at the origin (and everything far from it), so this test fails with it.
            if (std::string_view(cavity.name) != "dish" || translation > 0.0) {
                EXPECT_GT(wrong_before, 0) << cavity.name << " at " << translation;
            }
        }
    }
}

}  // namespace
}  // namespace csgrt
