#include "csgrt/mesh/mesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <thread>

#include "csgrt/accel/brute_force.h"
#include "csgrt/core/error.h"
#include "support/meshes.h"
#include "support/random.h"
#include "support/real_meshes.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

std::unique_ptr<Mesh> make_mesh(const test::TestMesh& mesh, bool double_precision = false) {
    MeshConfig config;
    config.double_precision = double_precision;
    return std::make_unique<Mesh>(TriangleMeshData{mesh.vertices, mesh.triangles, {}}, config);
}

/// The mesh's triangles exactly as stored (after validation), for independent checks.
std::vector<std::array<Point3, 3>> stored_triangles(const Mesh& mesh) {
    std::vector<std::array<Point3, 3>> corners(mesh.triangle_count());
    for (std::size_t i = 0; i < corners.size(); ++i) {
        for (int k = 0; k < 3; ++k) corners[i][k] = mesh.corner(i, k);
    }
    return corners;
}

/// Spans must be sorted, each non-empty (enter <= exit), pairwise disjoint.
void expect_well_formed(const SpanList& spans, const std::string& context) {
    for (std::size_t i = 0; i < spans.size(); ++i) {
        EXPECT_LE(spans[i].enter.t, spans[i].exit.t) << context;
        if (i > 0) {
            EXPECT_LE(spans[i - 1].exit.t, spans[i].enter.t) << context;
        }
    }
}

bool inside_spans(const SpanList& spans, double t) {
    return std::any_of(spans.begin(), spans.end(),
                       [&](const Span& span) { return t > span.enter.t && t < span.exit.t; });
}

// Nearest hits through the mesh (its structure from the factory) agree bit for bit with a
// brute-force loop over a triangle set built here from the mesh's validated triangles.
template <class Real>
void expect_agreement_with_brute_force(const Mesh& mesh, int rays, std::uint64_t seed) {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    for (std::size_t i = 0; i < mesh.triangle_count(); ++i) {
        const auto base = static_cast<std::uint32_t>(vertices.size());
        for (int k = 0; k < 3; ++k) vertices.push_back(mesh.corner(i, k));
        triangles.push_back({base, base + 1, base + 2});
    }
    const TriangleSet<Real> set(vertices, triangles);
    BruteForce<TriangleSet<Real>> brute;
    brute.build(set);
    QueryScratch scratch;
    test::Random random(seed);
    const Aabb box = mesh.bounds();
    int hits = 0;
    for (int i = 0; i < rays; ++i) {
        Ray ray = test::ray_toward(random, box, i);
        HitRecord expected, found;
        const bool expected_hit = brute.intersect(ray, expected, scratch);
        const bool hit = mesh.nearest_hit(ray, found, scratch);
        ASSERT_EQ(hit, expected_hit) << "ray " << i;
        EXPECT_EQ(mesh.any_hit(ray, scratch), expected_hit) << "ray " << i;
        if (!hit) continue;
        ++hits;
        EXPECT_EQ(found.t, expected.t) << "ray " << i;
        EXPECT_EQ(found.primitive, expected.primitive) << "ray " << i;
        EXPECT_EQ(found.u, expected.u);
        EXPECT_EQ(found.v, expected.v);
        EXPECT_EQ(found.shape, &mesh);
        EXPECT_EQ(found.instance_path, kNoIndex);
        EXPECT_FALSE(found.flip_normal);
    }
    EXPECT_GT(hits, rays / 3);
}

TEST(Mesh, NearestHitsAgreeWithBruteForce) {
    for (bool double_precision : {false, true}) {
        const auto cube = make_mesh(test::integer_cube(4), double_precision);
        const auto sphere = make_mesh(test::sphere_mesh(4), double_precision);
        if (double_precision) {
            expect_agreement_with_brute_force<double>(*cube, 20000, 1);
            expect_agreement_with_brute_force<double>(*sphere, 20000, 2);
        } else {
            expect_agreement_with_brute_force<float>(*cube, 20000, 1);
            expect_agreement_with_brute_force<float>(*sphere, 20000, 2);
        }
        EXPECT_EQ(cube->double_precision(), double_precision);
    }
}

TEST(Mesh, FinishedHitsLieOnTheTriangleWithRightHandedUnitNormals) {
    for (bool double_precision : {false, true}) {
        const auto mesh = make_mesh(test::sphere_mesh(3), double_precision);
        const auto corners = stored_triangles(*mesh);
        test::Random random(3);
        int hits = 0;
        for (int i = 0; i < 20000; ++i) {
            Ray ray = random.ray_between(Aabb(Point3(-3, -3, -3), Point3(3, 3, 3)),
                                         Aabb(Point3(-1, -1, -1), Point3(1, 1, 1)));
            if (i % 3 == 0) ray.origin = random.unit_vector() * random.uniform(0.0, 0.8);
            const std::optional<Hit> hit = mesh->intersect(ray);
            if (!hit) continue;
            ++hits;
            const auto& [a, b, c] = corners[hit->primitive_id];
            const Normal3 right_handed = (b - a).cross(c - a).normalized();
            EXPECT_NEAR(hit->geometric_normal.norm(), 1.0, 4 * kUnitRoundoff);
            EXPECT_NEAR((hit->geometric_normal - right_handed).norm(), 0.0, 1e-15);
            // Outward: the mesh is a convex polyhedron around the origin.
            EXPECT_GT(hit->geometric_normal.dot(hit->point), 0.0);
            EXPECT_NEAR(hit->shading_normal.norm(), 1.0, 4 * kUnitRoundoff);
            EXPECT_GT(hit->shading_normal.dot(hit->geometric_normal), 0.95);
            EXPECT_EQ(hit->front_face, ray.direction.dot(hit->geometric_normal) < 0.0);
            // On the triangle's plane to double rounding (the point comes from barycentrics)...
            EXPECT_LE(std::abs(right_handed.dot(hit->point - a)), 8 * kUnitRoundoff);
            // ... inside it ...
            const Eigen::Vector3d weights(right_handed.dot((c - b).cross(hit->point - b)),
                                          right_handed.dot((a - c).cross(hit->point - c)),
                                          right_handed.dot((b - a).cross(hit->point - a)));
            EXPECT_GE(weights.minCoeff(), -1e-15) << weights.transpose();
            // ... and where the ray meets it, to the float precision of the barycentrics.
            EXPECT_LE((hit->point - ray.at(hit->t)).norm(), 1e-6);
            EXPECT_GE(hit->uv.minCoeff(), 0.0);
            EXPECT_LE(hit->uv.sum(), 1.0);
            EXPECT_EQ(hit->shape, mesh.get());
            EXPECT_TRUE(ray.in_range(hit->t));
        }
        EXPECT_GT(hits, 8000);
    }
}

TEST(Mesh, IntervalHonouredAtBothEnds) {
    const auto cube = make_mesh(test::integer_cube(3));       // the box [0, 3]^3
    const Ray ray{Point3(-1, 1.25, 1.75), Vector3(1, 0, 0)};  // crosses x = 0 at t = 1, x = 3 at 4
    auto nearest = [&](double t_min, double t_max) {
        const std::optional<Hit> hit =
            cube->intersect(Ray{ray.origin, ray.direction, t_min, t_max});
        EXPECT_EQ(cube->occluded(Ray{ray.origin, ray.direction, t_min, t_max}), hit.has_value());
        return hit ? hit->t : -1.0;
    };
    EXPECT_EQ(nearest(0.0, kInfinity), 1.0);
    EXPECT_EQ(nearest(0.0, 1.0), 1.0);
    EXPECT_EQ(nearest(0.0, 0.999), -1.0);
    EXPECT_EQ(nearest(1.001, kInfinity), 4.0);
    EXPECT_EQ(nearest(4.0, 9.0), 4.0);
    EXPECT_EQ(nearest(4.001, 9.0), -1.0);
    EXPECT_EQ(nearest(2.0, 3.0), -1.0);
}

TEST(Mesh, InvalidRaysNeverHit) {
    const auto cube = make_mesh(test::integer_cube(2));
    const double nan = std::nan("");
    for (const Ray& ray :
         {Ray{Point3(nan, 1, 1), Vector3(1, 0, 0)}, Ray{Point3(-1, 1, 1), Vector3(nan, 0, 0)},
          Ray{Point3(-1, 1, 1), Vector3(0, 0, 0)}, Ray{Point3(-kInfinity, 1, 1), Vector3(1, 0, 0)},
          Ray{Point3(-1, 1, 1), Vector3(1, 0, 0), nan, kInfinity},
          Ray{Point3(-1, 1, 1), Vector3(1, 0, 0), 5.0, 4.0}}) {
        EXPECT_FALSE(cube->intersect(ray));
        EXPECT_FALSE(cube->occluded(ray));
        EXPECT_TRUE(cube->spans(ray).empty());
    }
}

TEST(Mesh, RejectsBadParameters) {
    const test::TestMesh cube = test::integer_cube(1);
    TriangleMeshData nan_vertex{cube.vertices, cube.triangles, {}};
    nan_vertex.vertices[0].x() = std::nan("");
    EXPECT_THROW(Mesh{nan_vertex}, InvalidParameter);
    TriangleMeshData bad_index{cube.vertices, cube.triangles, {}};
    bad_index.triangles[0][1] = 99;
    EXPECT_THROW(Mesh{bad_index}, InvalidParameter);
    EXPECT_THROW((Mesh{TriangleMeshData{cube.vertices, {}, {}}}), InvalidParameter);
    MeshConfig unknown;
    unknown.accelerator = "octree";
    EXPECT_THROW((Mesh{TriangleMeshData{cube.vertices, cube.triangles, {}}, unknown}),
                 InvalidParameter);
    EXPECT_THROW(Mesh::load("no_such_file.off"), MeshError);
}

TEST(Mesh, DefaultStructureIsARegisteredOne) {
    const std::string name = MeshConfig{}.accelerator;
    EXPECT_EQ(name, default_mesh_accelerator());
    const auto names = accelerator_names();
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end());
    const bool has_bvh = std::find(names.begin(), names.end(), "bvh") != names.end();
    EXPECT_EQ(name, has_bvh ? "bvh" : "brute");
    EXPECT_EQ(make_mesh(test::integer_cube(1))->accelerator_stats().primitives, 12u);
}

TEST(Mesh, OpenMeshIsNotASolid) {
    test::TestMesh open = test::integer_cube(2);
    open.triangles.pop_back();
    const auto mesh = make_mesh(open);
    EXPECT_FALSE(mesh->is_solid());
    EXPECT_FALSE(mesh->report().is_closed);
    EXPECT_TRUE(mesh->spans(Ray{Point3(-1, 0.5, 0.5), Vector3(1, 0, 0)}).empty());
    EXPECT_FALSE(mesh->contains(Point3(1, 1, 1)));
    EXPECT_TRUE(mesh->intersect(Ray{Point3(-1, 0.5, 0.5), Vector3(1, 0, 0)}));
}

// The box [0, n]^3 as a cube mesh: its surface is the zero set of max |p - c| - n/2.
test::SurfaceDescription box_surface(double n) {
    const Point3 center = Point3::Constant(n / 2);
    return test::SurfaceDescription{
        [=](const Point3& p) { return (p - center).cwiseAbs().maxCoeff() - n / 2; },
        [=](const Point3& p) {
            int axis;
            (p - center).cwiseAbs().maxCoeff(&axis);
            Vector3 gradient = Vector3::Zero();
            gradient[axis] = p[axis] > center[axis] ? 1.0 : -1.0;
            return gradient;
        },
        n / 2, Aabb(Point3::Zero(), Point3::Constant(n))};
}

TEST(Mesh, CubePropertiesOnRandomRays) {
    // Integer corners are exact in float, so hits lie on the box's faces to double rounding.
    for (bool double_precision : {false, true}) {
        const auto cube = make_mesh(test::integer_cube(4), double_precision);
        ASSERT_TRUE(cube->is_solid());
        const test::PropertyCounts counts =
            test::check_shape_properties(*cube, box_surface(4), 100000, 21);
        EXPECT_GT(counts.hits, 40000);
        EXPECT_GT(counts.span_checks, 100000);
    }
}

/// The interval of the line o + t d inside the box [0, n]^3 (slab test in long double).
bool box_interval(const Ray& ray, double n, long double& t0, long double& t1) {
    t0 = -std::numeric_limits<long double>::infinity();
    t1 = std::numeric_limits<long double>::infinity();
    for (int axis = 0; axis < 3; ++axis) {
        const long double o = ray.origin[axis], d = ray.direction[axis];
        if (d == 0) {
            if (o <= 0 || o >= n) return false;
            continue;
        }
        long double near = (0 - o) / d, far = (n - o) / d;
        if (near > far) std::swap(near, far);
        t0 = std::max(t0, near);
        t1 = std::min(t1, far);
    }
    return t0 < t1;
}

TEST(Mesh, RaysThroughSharedVerticesAndEdgesGiveOneSpan) {
    // Rays aimed exactly at the grid vertices and at the midpoints of the triangles' edges,
    // where the watertight test reports the crossing on every triangle sharing the point.
    // Each must give exactly one span, from the box's entry to its exit: no duplicate
    // crossing may open a spurious span or leave one without an exit.
    const int n = 3;
    const test::TestMesh grid = test::integer_cube(n);
    std::vector<Point3> targets(grid.vertices.begin(), grid.vertices.end());
    for (const auto& t : grid.triangles) {
        for (int k = 0; k < 3; ++k) {
            targets.push_back(0.5 * (grid.vertices[t[k]] + grid.vertices[t[(k + 1) % 3]]));
        }
    }
    const std::vector<Point3> origins = {Point3(-1, -2, -3),    Point3(-1, 1, 1),
                                         Point3(4.5, 1.5, -2),  Point3(-2, 5, 6),
                                         Point3(1.5, 1.5, 1.5), Point3(0.5, 2, 1)};
    for (bool double_precision : {false, true}) {
        const auto cube = make_mesh(grid, double_precision);
        int checked = 0;
        for (const Point3& origin : origins) {
            for (const Point3& target : targets) {
                const Ray ray{origin, target - origin, -kInfinity, kInfinity};
                long double t0, t1;
                // Lines that only touch the box (or run along a face) have no interior span.
                if (!box_interval(ray, n, t0, t1) || t1 - t0 < 1e-9) continue;
                ++checked;
                const SpanList spans = cube->spans(ray);
                const std::string context =
                    "from " + std::to_string(origin.x()) + "," + std::to_string(origin.y()) + "," +
                    std::to_string(origin.z()) + " to " + std::to_string(target.x()) + "," +
                    std::to_string(target.y()) + "," + std::to_string(target.z());
                ASSERT_EQ(spans.size(), 1u) << context;
                EXPECT_NEAR(spans[0].enter.t, double(t0), 1e-6 * (1 + std::abs(double(t0))))
                    << context;
                EXPECT_NEAR(spans[0].exit.t, double(t1), 1e-6 * (1 + std::abs(double(t1))))
                    << context;
                EXPECT_EQ(spans[0].enter.shape, cube.get());
                EXPECT_EQ(spans[0].exit.shape, cube.get());
                // From the origin on, the first boundary is the nearest hit, bit for bit.
                const Ray forward{origin, target - origin};
                const SpanList ahead = cube->spans(forward);
                const std::optional<Hit> hit = cube->intersect(forward);
                ASSERT_TRUE(hit) << context;
                ASSERT_EQ(ahead.size(), 1u) << context;
                const double first = ahead[0].enter.shape ? ahead[0].enter.t : ahead[0].exit.t;
                EXPECT_EQ(first, hit->t) << context;
                if (t0 < 0) {  // the origin is inside: the span began before it
                    EXPECT_EQ(ahead[0].enter.shape, nullptr) << context;
                    EXPECT_EQ(ahead[0].enter.t, -kInfinity) << context;
                }
            }
        }
        EXPECT_GT(checked, 1000);
    }
}

TEST(Mesh, AxisRaysThroughExactGridPointsCountEachCrossingOnce) {
    // Axis-parallel rays through every half-integer point of the face x = 0: everything is
    // exact in float, so edge functions are exactly zero at the grid's edges and vertices and
    // the tie rule alone decides. The crossings are at x = 0 (t = 1) and x = 3 (t = 4).
    const auto cube = make_mesh(test::integer_cube(3));
    for (int j = 1; j < 6; ++j) {
        for (int k = 1; k < 6; ++k) {
            const Ray ray{Point3(-1, 0.5 * j, 0.5 * k), Vector3(1, 0, 0), -kInfinity, kInfinity};
            const SpanList spans = cube->spans(ray);
            ASSERT_EQ(spans.size(), 1u) << j << " " << k;
            EXPECT_EQ(spans[0].enter.t, 1.0);
            EXPECT_EQ(spans[0].exit.t, 4.0);
            EXPECT_TRUE(cube->contains(Point3(1.5, 0.5 * j, 0.5 * k)));
            // Duplicates at the entry and at the exit would cancel; these rays cross the grid
            // point once and the inside of a triangle, at (3, y + 0.75, z + 0.375), once.
            if (j > 4 || k > 4) continue;
            const Vector3 slant(1, 0.25, 0.125);
            const Ray in{Point3(0, 0.5 * j, 0.5 * k) - slant, slant, -kInfinity, kInfinity};
            const SpanList through = cube->spans(in);
            ASSERT_EQ(through.size(), 1u) << j << " " << k;
            EXPECT_EQ(through[0].enter.t, 1.0);
            EXPECT_EQ(through[0].exit.t, 4.0);
            // A miscount at the exit would leave the line "inside" before its entry.
            const Ray back{Point3(0, 0.5 * j, 0.5 * k) + 4 * slant, -slant, -kInfinity, kInfinity};
            const SpanList returning = cube->spans(back);
            ASSERT_EQ(returning.size(), 1u) << j << " " << k;
            EXPECT_EQ(returning[0].enter.t, 1.0);
            EXPECT_EQ(returning[0].exit.t, 4.0);
            const Ray out{Point3(0, 0.5 * j, 0.5 * k) + slant, -slant};
            const SpanList leaving = cube->spans(out);
            ASSERT_EQ(leaving.size(), 1u) << j << " " << k;
            EXPECT_EQ(leaving[0].enter.t, -kInfinity);
            EXPECT_EQ(leaving[0].exit.t, 1.0);
        }
    }
}

TEST(Mesh, RaysAlongFacesGiveWellFormedSpans) {
    // A ray lying in a face's plane or along an edge grazes the surface: its points are on
    // the boundary, so any classification is right, but the spans must stay well formed.
    const auto cube = make_mesh(test::integer_cube(3));
    for (const Ray& ray : {Ray{Point3(-1, 1.5, 3), Vector3(1, 0, 0), -kInfinity, kInfinity},
                           Ray{Point3(-1, 0, 0), Vector3(1, 0, 0), -kInfinity, kInfinity},
                           Ray{Point3(-1, -1, 3), Vector3(1, 1, 0), -kInfinity, kInfinity},
                           Ray{Point3(1.5, 1.5, 1.5), Vector3(1, 1, 1), -kInfinity, kInfinity}}) {
        const SpanList spans = cube->spans(ray);
        expect_well_formed(spans, "grazing");
        EXPECT_LE(spans.size(), 2u);
    }
}

TEST(Mesh, RayFromInsideStartsItsSpanAtMinusInfinity) {
    const auto sphere = make_mesh(test::sphere_mesh(3));
    const Ray ray{Point3(0.1, 0.2, -0.1), Vector3(0.3, -0.5, 2.0)};
    const SpanList spans = sphere->spans(ray);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.shape, nullptr);
    EXPECT_EQ(spans[0].enter.t, -kInfinity);
    const std::optional<Hit> hit = sphere->intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_EQ(spans[0].exit.t, hit->t);
    EXPECT_EQ(spans[0].exit.primitive, hit->primitive_id);
    EXPECT_TRUE(sphere->contains(ray.origin));
}

TEST(Mesh, SphereMeshSpansAgreeWithTheAnalyticSphereUpToTessellation) {
    // sphere_mesh's vertices lie on the unit sphere, so the mesh lies between the sphere and
    // the sphere of radius r_in, the smallest distance from the centre to a triangle's plane.
    // Each mesh span boundary must lie between the two spheres' crossings.
    for (bool double_precision : {false, true}) {
        const auto mesh = make_mesh(test::sphere_mesh(4), double_precision);
        double r_in = 1.0;
        for (const auto& [a, b, c] : stored_triangles(*mesh)) {
            const Normal3 n = (b - a).cross(c - a).normalized();
            r_in = std::min(r_in, std::abs(n.dot(a)));
        }
        ASSERT_GT(r_in, 0.99);
        const double slack = 1e-6;  // float corners: the sphere's vertices rounded to float
        test::Random random(5);
        int crossing = 0, missing = 0;
        for (int i = 0; i < 20000; ++i) {
            Ray ray = random.ray_between(Aabb(Point3(-3, -3, -3), Point3(3, 3, 3)),
                                         Aabb(Point3(-1, -1, -1), Point3(1, 1, 1)));
            ray.t_min = -kInfinity;
            const SpanList spans = mesh->spans(ray);
            expect_well_formed(spans, "sphere");
            // The line's closest approach to the centre, and its crossings of radius r.
            const double a = ray.direction.squaredNorm();
            const double t_mid = -ray.origin.dot(ray.direction) / a;
            const double distance = ray.at(t_mid).norm();
            auto roots = [&](double r, double& t0, double& t1) {
                const double half = std::sqrt(std::max(0.0, r * r - distance * distance) / a);
                t0 = t_mid - half;
                t1 = t_mid + half;
            };
            if (distance > 1.0 + slack) {
                EXPECT_TRUE(spans.empty()) << "ray " << i;
                ++missing;
            } else if (distance < r_in - slack) {
                ++crossing;
                ASSERT_EQ(spans.size(), 1u) << "ray " << i;
                double outer0, outer1, inner0, inner1;
                roots(1.0 + slack, outer0, outer1);
                roots(r_in - slack, inner0, inner1);
                EXPECT_GE(spans[0].enter.t, outer0) << i;
                EXPECT_LE(spans[0].enter.t, inner0) << i;
                EXPECT_GE(spans[0].exit.t, inner1) << i;
                EXPECT_LE(spans[0].exit.t, outer1) << i;
            }
        }
        EXPECT_GT(crossing, 5000);
        EXPECT_GT(missing, 2000);
    }
}

/// Point membership by an independent count: crossings of a random ray with every stored
/// triangle (Moeller-Trumbore in double), parity; rays that pass near an edge or start near
/// the surface are discarded and another direction drawn.
bool brute_force_inside(const std::vector<std::array<Point3, 3>>& triangles, const Point3& p,
                        test::Random& random) {
    while (true) {
        const Vector3 d = random.unit_vector();
        bool clear = true;
        int crossings = 0;
        for (const auto& [a, b, c] : triangles) {
            const Vector3 e1 = b - a, e2 = c - a, q = d.cross(e2);
            const double det = e1.dot(q);
            if (std::abs(det) < 1e-12 * e1.norm() * e2.norm()) continue;
            const Vector3 s = p - a;
            const double u = s.dot(q) / det;
            const Vector3 r = s.cross(e1);
            const double v = d.dot(r) / det;
            const double t = e2.dot(r) / det;
            const double margin = 1e-9;
            if (u < -margin || v < -margin || u + v > 1 + margin || t < -margin) continue;
            if (u < margin || v < margin || u + v > 1 - margin || t < margin) clear = false;
            ++crossings;
        }
        if (clear) return crossings % 2 == 1;
    }
}

void expect_membership_agrees(const Mesh& mesh, int points, int rays, std::uint64_t seed) {
    const auto triangles = stored_triangles(mesh);
    test::Random random(seed);
    const Aabb box = mesh.bounds();
    const double scale = box.diagonal().norm();
    int inside = 0;
    for (int i = 0; i < points; ++i) {
        const Point3 p = random.in_box(test::enlarged(box, 0.05));
        const bool expected = brute_force_inside(triangles, p, random);
        EXPECT_EQ(mesh.contains(p), expected) << "point " << i << ": " << p.transpose();
        inside += expected;
    }
    EXPECT_GT(inside, points / 20);
    // Spans along random lines agree with membership at sample points off their boundaries.
    int samples = 0;
    for (int i = 0; i < rays; ++i) {
        Ray ray = random.ray_between(test::enlarged(box, 1.0), box);
        ray.t_min = -kInfinity;
        const SpanList spans = mesh.spans(ray);
        expect_well_formed(spans, "ray " + std::to_string(i));
        const double margin = 1e-6 * scale / ray.direction.norm();
        for (int k = 0; k < 8; ++k) {
            const double t = random.uniform(-0.5, 2.0);
            const bool near = std::any_of(spans.begin(), spans.end(), [&](const Span& span) {
                return std::abs(t - span.enter.t) < margin || std::abs(t - span.exit.t) < margin;
            });
            if (near) continue;
            ++samples;
            EXPECT_EQ(mesh.contains(ray.at(t)), inside_spans(spans, t))
                << "ray " << i << " t " << t;
        }
    }
    EXPECT_GT(samples, 6 * rays);
}

TEST(Mesh, SphereMeshMembershipAgreesWithBruteForceParityAndSpans) {
    expect_membership_agrees(*make_mesh(test::sphere_mesh(3)), 2000, 2000, 6);
}

TEST(Mesh, ArmadilloMembershipAgreesWithBruteForceParityAndSpans) {
    const std::filesystem::path path = test::real_mesh("armadillo");
    if (path.empty()) GTEST_SKIP() << "data/fetch-meshes could not provide the armadillo";
    const std::shared_ptr<Mesh> armadillo = Mesh::load(path);
    EXPECT_EQ(armadillo->triangle_count(), 52000u);
    ASSERT_TRUE(armadillo->is_solid());
    expect_membership_agrees(*armadillo, 400, 300, 7);
}

TEST(Mesh, ConcurrentQueriesGiveTheSameAnswers) {
    const auto sphere = make_mesh(test::sphere_mesh(3));
    test::Random random(8);
    std::vector<Ray> rays;
    for (int i = 0; i < 2000; ++i) {
        rays.push_back(random.ray_between(Aabb(Point3(-2, -2, -2), Point3(2, 2, 2)),
                                          Aabb(Point3(-1, -1, -1), Point3(1, 1, 1))));
    }
    auto answers = [&]() {
        std::vector<double> out;
        for (const Ray& ray : rays) {
            const std::optional<Hit> hit = sphere->intersect(ray);
            out.push_back(hit ? hit->t : -1.0);
            for (const Span& span : sphere->spans(ray)) {
                out.push_back(span.enter.t);
                out.push_back(span.exit.t);
            }
            out.push_back(sphere->contains(ray.at(0.7)) ? 1.0 : 0.0);
        }
        return out;
    };
    const std::vector<double> expected = answers();
    std::vector<std::vector<double>> results(4);
    std::vector<std::thread> threads;
    for (auto& result : results) threads.emplace_back([&] { result = answers(); });
    for (std::thread& thread : threads) thread.join();
    for (const auto& result : results) EXPECT_EQ(result, expected);
}

TEST(Mesh, LoadsFixtureFilesAsSolids) {
    const auto box =
        Mesh::load(std::filesystem::path(CSGRT_SOURCE_DIR) / "tests/data/meshes/box.off");
    EXPECT_TRUE(box->is_solid());
    EXPECT_EQ(box->report().format, "off");
    EXPECT_EQ(box->bounds().lower, Point3(0, 0, 0));
    EXPECT_EQ(box->bounds().upper, Point3(2, 3, 4));
    const SpanList spans = box->spans(Ray{Point3(1, 1, -1), Vector3(0, 0, 1)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 1.0);
    EXPECT_EQ(spans[0].exit.t, 5.0);
}

}  // namespace
}  // namespace csgrt
