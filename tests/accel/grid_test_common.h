#pragma once

// Scenes, ray sets, the brute-force agreement check and the checks every structure passes alike
// (invalid rays, the empty set, one triangle, identical copies), shared by the regular grid,
// hierarchical grid and ray classification tests.

#include <gtest/gtest.h>

#include <algorithm>
#include <initializer_list>
#include <memory>
#include <thread>
#include <tuple>
#include <vector>

#include "csgrt/accel/accelerator.h"
#include "csgrt/accel/brute_force.h"
#include "csgrt/accel/factory.h"
#include "csgrt/accel/regular_grid.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/sphere.h"
#include "support/meshes.h"
#include "support/random.h"
#include "support/rays.h"
#include "support/unbounded_plane.h"

namespace csgrt::test {

inline constexpr float kInfinityF = std::numeric_limits<float>::infinity();

/// Appends `other` to `mesh`, its vertices mapped by p -> scale * p + offset.
inline void append(TestMesh& mesh, const TestMesh& other, double scale = 1.0,
                   const Vector3& offset = Vector3::Zero()) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (const Eigen::Vector3d& v : other.vertices) mesh.vertices.push_back(scale * v + offset);
    for (const auto& [a, b, c] : other.triangles)
        mesh.triangles.push_back({a + base, b + base, c + base});
}

/// A soup of `count` random triangles in [0, 10]^3, most of them long (up to the box's size)
/// and thin (width 1e-3 to 1e-1 of their length) in random directions: the case that fills
/// many cells per triangle and makes the float test's t least accurate.
inline TestMesh long_thin_soup(int count, std::uint64_t seed) {
    Random random(seed);
    TestMesh mesh;
    const Aabb box(Point3(0, 0, 0), Point3(10, 10, 10));
    for (int i = 0; i < count; ++i) {
        const Point3 a = random.in_box(box);
        Point3 b = a + random.unit_vector() * random.uniform(0.1, 10.0);
        b = b.cwiseMax(box.lower).cwiseMin(box.upper);
        const double width = (b - a).norm() * std::pow(10.0, random.uniform(-3.0, -1.0));
        const Point3 c = 0.5 * (a + b) + random.unit_vector() * width;
        const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.insert(mesh.vertices.end(), {a, b, c});
        mesh.triangles.push_back({base, base + 1, base + 2});
    }
    return mesh;
}

/// "Teapot in a stadium": a dense unit sphere mesh (2048 triangles) at the origin, standing on
/// a floor and between two walls made of a few huge triangles 400 units across.
inline TestMesh teapot_in_stadium() {
    TestMesh mesh = sphere_mesh(4);
    const double s = 200.0;
    TestMesh stadium;
    stadium.vertices = {{-s, -1.5, -s}, {s, -1.5, -s}, {s, -1.5, s}, {-s, -1.5, s},
                        {-s, -1.5, -s}, {s, -1.5, -s}, {s, 60, -s},  {-s, 60, -s},
                        {-s, -1.5, -s}, {-s, -1.5, s}, {-s, 60, s},  {-s, 60, -s}};
    stadium.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}, {8, 9, 10}, {8, 10, 11}};
    append(mesh, stadium);
    return mesh;
}

/// `count` random triangles lying exactly in the plane z = 0 (flat bounds).
inline TestMesh flat_soup(int count, std::uint64_t seed) {
    Random random(seed);
    TestMesh mesh;
    for (int i = 0; i < count; ++i) {
        const Point3 a(random.uniform(0, 10), random.uniform(0, 10), 0.0);
        const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
        for (int k = 0; k < 3; ++k)
            mesh.vertices.push_back(a + Vector3(random.uniform(-1, 1), random.uniform(-1, 1), 0));
        mesh.triangles.push_back({base, base + 1, base + 2});
    }
    return mesh;
}

/// `count` copies of one triangle: every primitive in the same cells, every hit a tie.
inline TestMesh identical_triangles(int count) {
    TestMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0.25}, {0, 1, 0.5}};
    for (int i = 0; i < count; ++i) mesh.triangles.push_back({0, 1, 2});
    return mesh;
}

/// `count` random spheres (radii 0.02 to 0.3) in [0, 10]^3, some overlapping.
inline std::vector<std::shared_ptr<const Shape>> random_spheres(int count, std::uint64_t seed) {
    Random random(seed);
    std::vector<std::shared_ptr<const Shape>> shapes;
    const Aabb box(Point3(0, 0, 0), Point3(10, 10, 10));
    for (int i = 0; i < count; ++i)
        shapes.push_back(std::make_shared<Sphere>(random.in_box(box), random.uniform(0.02, 0.3)));
    return shapes;
}

/// The exact answer of a structure for one ray, to compare across structures and threads.
struct Answer {
    bool hit = false;
    HitRecord record;
};

/// The records' (member, t) pairs, sorted: all_hits compared as sets.
template <class Set>
std::vector<std::tuple<std::uint32_t, double, float, float>> hit_set(
    const std::vector<HitRecord>& hits) {
    std::vector<std::tuple<std::uint32_t, double, float, float>> set;
    for (const HitRecord& h : hits) set.emplace_back(member_of<Set>(h), h.t, h.u, h.v);
    std::sort(set.begin(), set.end());
    return set;
}

/// What one agreement run saw.
struct AgreementCounts {
    int rays = 0;
    int hits = 0;
    int all_hits_checked = 0;
};

/// Checks each of `structures` against brute force on every ray: the same hit or miss,
/// bit-identical t, the same member, primitive and barycentrics (the tie rule of PrimitiveSet
/// makes the nearest hit unique), occluded == intersect for both entry points, and (every
/// `all_hits_every`th ray) the same all_hits as a set with no member twice. Brute force
/// answers each ray once for all structures. Stops after a few failures so a broken
/// structure does not flood the log.
template <class Set>
AgreementCounts expect_agreement(std::initializer_list<const Accelerator<Set>*> structures,
                                 const BruteForce<Set>& brute, const std::vector<Ray>& rays,
                                 int all_hits_every = 8) {
    AgreementCounts counts;
    QueryScratch scratch;
    int failures = 0;
    std::vector<HitRecord> expected_all, actual_all;
    for (std::size_t i = 0; i < rays.size() && failures < 5; ++i) {
        const Ray& ray = rays[i];
        ++counts.rays;
        HitRecord expected;
        const bool expected_hit = brute.intersect(ray, expected, scratch);
        counts.hits += expected_hit;
        const bool check_all = all_hits_every > 0 && i % std::size_t(all_hits_every) == 0;
        if (check_all) {
            expected_all.clear();
            brute.all_hits(ray, expected_all, scratch);
            ++counts.all_hits_checked;
        }
        for (const Accelerator<Set>* structure : structures) {
            HitRecord actual;
            const bool actual_hit = structure->intersect(ray, actual, scratch);
            bool ok = expected_hit == actual_hit;
            if (ok && expected_hit) {
                ok = expected.t == actual.t && member_of<Set>(expected) == member_of<Set>(actual) &&
                     expected.primitive == actual.primitive && expected.u == actual.u &&
                     expected.v == actual.v && expected.shape == actual.shape;
            }
            TraversalCounters counters;
            ok = ok && structure->occluded(ray, scratch) == expected_hit &&
                 structure->occluded_counted(ray, scratch, counters) == expected_hit;
            HitRecord counted;
            ok = ok &&
                 structure->intersect_counted(ray, counted, scratch, counters) == expected_hit &&
                 (!expected_hit || counted.t == expected.t);
            if (!ok) {
                ++failures;
                ADD_FAILURE() << "ray " << i << " origin (" << ray.origin.transpose()
                              << ") direction (" << ray.direction.transpose() << ") [" << ray.t_min
                              << ", " << ray.t_max << "]: brute " << expected_hit << " t "
                              << expected.t << " member " << member_of<Set>(expected) << ", "
                              << structure->name() << " " << actual_hit << " t " << actual.t
                              << " member " << member_of<Set>(actual);
            }
            if (check_all) {
                actual_all.clear();
                structure->all_hits(ray, actual_all, scratch);
                if (hit_set<Set>(expected_all) != hit_set<Set>(actual_all)) {
                    ++failures;
                    ADD_FAILURE() << "all_hits differ on ray " << i << ": brute "
                                  << expected_all.size() << " hits, " << structure->name() << " "
                                  << actual_all.size();
                }
            }
        }
    }
    return counts;
}

/// expect_agreement for one structure.
template <class Set>
AgreementCounts expect_agreement(const Accelerator<Set>& structure, const BruteForce<Set>& brute,
                                 const std::vector<Ray>& rays, int all_hits_every = 8) {
    return expect_agreement({&structure}, brute, rays, all_hits_every);
}

/// Valid rays with odd numbers, answered as brute force answers them: directions with
/// denormal and huge components from `outside`, an origin 10^12 away on outside's line along
/// x, and a direction of components near 1e-150 from `inside`.
template <class Set>
void expect_odd_rays_agree(const Accelerator<Set>& structure, const BruteForce<Set>& brute,
                           const Point3& outside, const Point3& inside) {
    const std::vector<Ray> odd = {Ray{outside, Vector3(1, 1e-310, -1e-310)},
                                  Ray{outside, Vector3(1e30, 1e-10, 0)},
                                  Ray{Point3(-1e12, outside.y(), outside.z()), Vector3(1, 0, 0)},
                                  Ray{inside, Vector3(1e-150, 2e-150, 3e-150)}};
    expect_agreement(structure, brute, odd, 1);
}

/// Answers `rays` from `threads` threads at once (each a strided share, each with its own
/// scratch) and checks every answer equals the single-threaded one.
template <class Set>
void expect_same_answers_concurrently(const Accelerator<Set>& structure,
                                      const std::vector<Ray>& rays, int threads) {
    std::vector<Answer> reference(rays.size());
    QueryScratch scratch;
    for (std::size_t i = 0; i < rays.size(); ++i)
        reference[i].hit = structure.intersect(rays[i], reference[i].record, scratch);
    std::vector<Answer> answers(rays.size());
    std::vector<char> occluded(rays.size());
    std::vector<std::thread> pool;
    for (int k = 0; k < threads; ++k) {
        pool.emplace_back([&, k] {
            QueryScratch own;
            for (std::size_t i = std::size_t(k); i < rays.size(); i += std::size_t(threads)) {
                answers[i].hit = structure.intersect(rays[i], answers[i].record, own);
                occluded[i] = structure.occluded(rays[i], own);
            }
        });
    }
    for (std::thread& thread : pool) thread.join();
    int mismatches = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        mismatches += answers[i].hit != reference[i].hit ||
                      (reference[i].hit && (answers[i].record.t != reference[i].record.t ||
                                            member_of<Set>(answers[i].record) !=
                                                member_of<Set>(reference[i].record))) ||
                      bool(occluded[i]) != reference[i].hit;
    }
    EXPECT_EQ(mismatches, 0);
}

/// A `Structure` built over `mesh` in precision Real answers `count` incoherent rays around the
/// mesh (seed `seed`) and `count` camera rays toward `camera_target` (seed + 1) from four threads
/// at once as it answers them from one (expect_same_answers_concurrently).
template <class Real, template <class> class Structure>
void expect_concurrent_answers_on_mesh(const TestMesh& mesh, const Aabb& camera_target, int count,
                                       std::uint64_t seed) {
    const TriangleSet<Real> set(mesh.vertices, mesh.triangles);
    Structure<TriangleSet<Real>> structure;
    structure.build(set);
    std::vector<Ray> rays = incoherent_rays(mesh_bounds(mesh), count, seed);
    const std::vector<Ray> camera = camera_rays(camera_target, count, seed + 1);
    rays.insert(rays.end(), camera.begin(), camera.end());
    expect_same_answers_concurrently(structure, rays, 4);
}

/// The cell boundary plane of `grid` along `axis` nearest to `x`, computed as the grid does.
inline double boundary_near(const detail::GridGeometry& grid, int axis, double x) {
    const double i = std::round((x - grid.bounds.lower[axis]) / grid.cell_size[axis]);
    return grid.bounds.lower[axis] + i * grid.cell_size[axis];
}

/// The box [990, 1010]^3 framed by its bottom and top faces (z = 990 and z = 1010, eight
/// triangles each, so its bounds do not depend on what else is inside) plus `inner`: a scene
/// far enough from the origin for float rounding to be coarse (6e-5), open to rays along x
/// and y.
inline TestMesh framed(const TestMesh& inner) {
    TestMesh mesh;
    for (const double z : {990.0, 1010.0}) {
        for (int i = 0; i < 2; ++i) {
            for (int j = 0; j < 2; ++j) {
                const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
                const double x = 990.0 + 10.0 * i, y = 990.0 + 10.0 * j;
                mesh.vertices.insert(mesh.vertices.end(),
                                     {Point3(x, y, z), Point3(x + 10, y, z),
                                      Point3(x + 10, y + 10, z), Point3(x, y + 10, z)});
                mesh.triangles.push_back({base, base + 1, base + 2});
                mesh.triangles.push_back({base, base + 2, base + 3});
            }
        }
    }
    append(mesh, inner);
    return mesh;
}

/// A float triangle reports hits up to a rounding error outside itself (the ray origin is
/// rounded to float, and zero edge functions count as inside). Builds a case where that
/// matters: a triangle whose edge is the float next to a cell boundary b, and a ray that
/// passes on the other side of b, just outside the triangle, yet rounds onto its edge.
/// `build` is called with each mesh and returns the grid geometry it built; `check` gets the
/// final mesh and the ray.
template <class Build, class Check>
void float_edge_next_to_a_cell_boundary(Build&& build, Check&& check) {
    TestMesh placeholder;
    placeholder.vertices = {{999, 999, 995}, {1001, 999, 995}, {1000, 1001, 995}};
    placeholder.triangles = {{0, 1, 2}};
    // The placeholder keeps the primitive count, so the real build has the same cells.
    const detail::GridGeometry grid = build(framed(placeholder));
    const double b = boundary_near(grid, 0, 997.0);
    // The floats on either side of b.
    float below_float = float(b);
    if (double(below_float) >= b) below_float = std::nextafter(below_float, -kInfinityF);
    const double below = below_float, above = std::nextafter(below_float, kInfinityF);
    ASSERT_LT(below, b);
    ASSERT_GT(above, b);
    TestMesh triangle;
    Ray ray{Point3(0, 1000, 1005), Vector3(0, 0, -1)};
    if (b - below < above - b) {
        // The triangle ends at `below`; the ray, just right of b, rounds down onto its edge.
        triangle.vertices = {{below, 999, 995}, {below, 1001, 995}, {below - 2, 1000, 995}};
        ray.origin.x() = b + 1e-9;
    } else {
        triangle.vertices = {{above, 999, 995}, {above, 1001, 995}, {above + 2, 1000, 995}};
        ray.origin.x() = b - 1e-9;
    }
    ASSERT_EQ(double(float(ray.origin.x())), triangle.vertices[0].x());
    triangle.triangles = {{0, 1, 2}};
    const TestMesh mesh = framed(triangle);
    ASSERT_EQ(build(mesh).cell_size, grid.cell_size);
    check(mesh, ray);
}

/// Two congruent triangles facing the x axis, one on each side of a cell boundary b and one
/// Real apart (the Real numbers next to b), the far one with the lower index: float rounding of
/// t makes many rays along +x tie or reverse their order, and the far one then wins, so a
/// search that stopped at the cell boundary after finding the near one would be wrong.
/// With a `gap`, the twins are at b -+ gap / 2 instead. Returns the mesh; `build` as in
/// float_edge_next_to_a_cell_boundary.
template <class Real, class Build>
TestMesh twin_triangles_across_a_cell_boundary(Build&& build, double gap = 0.0) {
    TestMesh placeholder;
    placeholder.vertices = {{999, 999, 999}, {999, 1003, 999}, {999, 999, 1003},
                            {998, 999, 999}, {998, 1003, 999}, {998, 999, 1003}};
    placeholder.triangles = {{0, 1, 2}, {3, 4, 5}};
    const detail::GridGeometry grid = build(framed(placeholder));
    const double b = boundary_near(grid, 0, 1000.0);
    constexpr Real kInfinityReal = std::numeric_limits<Real>::infinity();
    Real below = Real(b);
    if (double(below) >= b) below = std::nextafter(below, -kInfinityReal);
    Real above = std::nextafter(below, kInfinityReal);
    if (gap > 0.0) {
        below = Real(b - 0.5 * gap);
        above = Real(b + 0.5 * gap);
    }
    TestMesh twins;
    twins.vertices = {{above, 999, 999}, {above, 1003, 999}, {above, 999, 1003},
                      {below, 999, 999}, {below, 1003, 999}, {below, 999, 1003}};
    twins.triangles = {{0, 1, 2}, {3, 4, 5}};
    const TestMesh mesh = framed(twins);
    EXPECT_EQ(build(mesh).cell_size, grid.cell_size);
    return mesh;
}

/// Rays along +x from far before the twins of twin_triangles_across_a_cell_boundary (so
/// their float distances round to the same value), through random points of them.
inline std::vector<Ray> rays_through_twins(int count, std::uint64_t seed,
                                           double distance = 2000.0) {
    Random random(seed);
    std::vector<Ray> rays;
    for (int i = 0; i < count; ++i) {
        const double y = random.uniform(999.0, 1001.0),
                     z = random.uniform(999.0, 1003.0 - (y - 999.0));
        rays.push_back(Ray{Point3(1000.0 - distance * random.uniform(0.5, 2.0), y, z),
                           Vector3(random.uniform(0.5, 2), 0, 0)});
    }
    return rays;
}

/// Rays no query may answer (NaN, infinite or zero directions and origins, t_min > t_max).
inline std::vector<Ray> invalid_rays() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {Ray{Point3(nan, 0, 0), Vector3(1, 0, 0)},
            Ray{Point3(0, 0, 0), Vector3(nan, 1, 0)},
            Ray{Point3(kInfinity, 0, 0), Vector3(-1, 0, 0)},
            Ray{Point3(0, 0, 0), Vector3(kInfinity, 1, 1)},
            Ray{Point3(0.5, 0.5, 0.5), Vector3(0, 0, 0)},
            Ray{Point3(0.5, 0.5, -5), Vector3(0, 0, 1), 3.0, 2.0},
            Ray{Point3(0.5, 0.5, -5), Vector3(0, 0, 1), nan, 10.0},
            Ray{Point3(0.5, 0.5, -5), Vector3(0, 0, 1), 0.0, nan}};
}

/// A triangle set in precision Real built from `mesh`, with brute force over it: the oracle for
/// tests of the set itself or of structures they build in several ways. Not movable: brute
/// force points into the set.
template <class Real>
struct BruteForceMesh {
    explicit BruteForceMesh(const TestMesh& mesh) : set(mesh.vertices, mesh.triangles) {
        brute.build(set);
    }
    BruteForceMesh(const BruteForceMesh&) = delete;
    BruteForceMesh& operator=(const BruteForceMesh&) = delete;

    TriangleSet<Real> set;
    BruteForce<TriangleSet<Real>> brute;
};

/// A triangle set in precision Real built from `mesh`, with brute force and a `Structure` built
/// over it. Not movable: both structures point into the set.
template <class Real, template <class> class Structure>
struct BuiltMesh {
    using Set = TriangleSet<Real>;

    template <class... Config>
    explicit BuiltMesh(const TestMesh& mesh, const Config&... config)
        : set(mesh.vertices, mesh.triangles) {
        brute.build(set);
        structure.build(set, config...);
    }
    BuiltMesh(const BuiltMesh&) = delete;
    BuiltMesh& operator=(const BuiltMesh&) = delete;

    Set set;
    BruteForce<Set> brute;
    Structure<Set> structure;
};

/// Camera-like and incoherent rays around `box`, and a tenth as many axis-parallel ones.
inline std::vector<Ray> agreement_rays(const Aabb& box, int camera, int incoherent,
                                       std::uint64_t seed) {
    std::vector<Ray> rays = camera_rays(box, camera, seed);
    const std::vector<Ray> more = incoherent_rays(box, incoherent, seed + 1);
    const std::vector<Ray> axes = axis_rays(box, incoherent / 10, seed + 2);
    rays.insert(rays.end(), more.begin(), more.end());
    rays.insert(rays.end(), axes.begin(), axes.end());
    return rays;
}

/// Builds a `Structure` (with `config`) and brute force over `mesh` in precision Real and
/// checks them against each other on agreement_rays; a good share of the rays must hit (a
/// structure that missed everything would agree with nothing). Returns the rays checked.
template <class Real, template <class> class Structure, class... Config>
int expect_agreement_on_mesh(const TestMesh& mesh, int camera, int incoherent, std::uint64_t seed,
                             const Config&... config) {
    const BuiltMesh<Real, Structure> built(mesh, config...);
    const AgreementCounts counts = expect_agreement(
        built.structure, built.brute, agreement_rays(mesh_bounds(mesh), camera, incoherent, seed));
    EXPECT_GT(counts.hits, counts.rays / 5) << built.structure.stats().details;
    return counts.rays;
}

/// Rays in and just off the plane z = 0 of flat_soup (in it, grazing it within 1e-6) and rays
/// from above it, from random points over [-2, 12]^2.
inline std::vector<Ray> rays_along_a_plane(int count, std::uint64_t seed) {
    Random random(seed);
    std::vector<Ray> rays;
    for (int n = 0; n < count; ++n) {
        const Point3 origin(random.uniform(-2, 12), random.uniform(-2, 12), 0.0);
        Vector3 direction = random.unit_vector();
        switch (n % 3) {
            case 0:
                direction.z() = 0.0;
                break;
            case 1:
                direction.z() = random.uniform(-1e-6, 1e-6);
                break;
            default:
                rays.push_back(Ray{origin + Vector3(0, 0, 3), direction});
        }
        rays.push_back(Ray{origin, direction});
    }
    return rays;
}

/// Appends two rays lying exactly in a cell boundary plane of `grid` (the n-th of a sequence:
/// the plane's axis cycles, and every second ray also lies in a plane of a second axis, so it
/// runs along a cell edge), from a random point of the grid's bounds enlarged by `margin`; and
/// the same ray moved into an integer plane of the mesh (integer_cube(6)).
inline void add_cell_boundary_rays(const detail::GridGeometry& grid, int n, double margin,
                                   Random& random, std::vector<Ray>& rays) {
    auto plane = [&](int axis, int i) {
        return grid.bounds.lower[axis] + i * grid.cell_size[axis];
    };
    const int axis = n % 3, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    Point3 origin = random.in_box(enlarged(grid.bounds, margin));
    Vector3 direction = random.unit_vector();
    // In a boundary plane (including the faces, i = 0 and i = resolution).
    origin[axis] = plane(axis, random.integer(0, grid.resolution[axis]));
    direction[axis] = 0.0;
    if (n % 2 == 0) {
        // Along a cell edge: also in a plane of a second axis, moving along the third.
        origin[a1] = plane(a1, random.integer(0, grid.resolution[a1]));
        direction[a1] = 0.0;
        direction[a2] = n % 4 ? 1.0 : -2.0;
    }
    rays.push_back(Ray{origin, direction});
    Point3 on_mesh_plane = origin;
    on_mesh_plane[axis] = random.integer(0, 6);
    rays.push_back(Ray{on_mesh_plane, direction});
}

/// No query of `structure` answers any of invalid_rays(): intersect, occluded (counted or
/// not) and all_hits.
template <class Set>
void expect_invalid_rays_answer_nothing(const Accelerator<Set>& structure) {
    QueryScratch scratch;
    for (const Ray& ray : invalid_rays()) {
        HitRecord record;
        TraversalCounters counters;
        EXPECT_FALSE(structure.intersect(ray, record, scratch));
        EXPECT_FALSE(structure.intersect_counted(ray, record, scratch, counters));
        EXPECT_FALSE(structure.occluded(ray, scratch));
        EXPECT_FALSE(structure.occluded_counted(ray, scratch, counters));
        std::vector<HitRecord> hits;
        structure.all_hits(ray, hits, scratch);
        EXPECT_TRUE(hits.empty());
    }
}

/// A structure built over an empty set answers nothing.
template <class Set>
void expect_empty_set_answers_nothing(const Accelerator<Set>& structure) {
    QueryScratch scratch;
    HitRecord record;
    const Ray ray{Point3(0, 0, -1), Vector3(0, 0, 1)};
    EXPECT_FALSE(structure.intersect(ray, record, scratch));
    EXPECT_FALSE(structure.occluded(ray, scratch));
    std::vector<HitRecord> hits;
    structure.all_hits(ray, hits, scratch);
    EXPECT_TRUE(hits.empty());
}

/// A `Structure` built over an empty triangle set in precision Real answers nothing
/// (expect_empty_set_answers_nothing), and its stats count no primitive and no reference.
template <class Real, template <class> class Structure>
void expect_empty_structure_answers_nothing() {
    const TriangleSet<Real> empty;
    Structure<TriangleSet<Real>> structure;
    structure.build(empty);
    expect_empty_set_answers_nothing(structure);
    EXPECT_EQ(structure.stats().primitives, 0u) << structure.name();
    EXPECT_EQ(structure.stats().references, 0u) << structure.name();
}

/// The triangle (0, 0, 0), (2, 0, 0), (0, 2, 0), for expect_single_triangle_answers.
inline TestMesh single_triangle() {
    TestMesh mesh;
    mesh.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    mesh.triangles = {{0, 1, 2}};
    return mesh;
}

/// A structure over single_triangle(): the exact hit t = 0.5 of a ray along z through it, the
/// closed interval [t_min, t_max] honoured at both ends, and a miss beside it.
template <class Set>
void expect_single_triangle_answers(const Accelerator<Set>& structure) {
    QueryScratch scratch;
    HitRecord record;
    ASSERT_TRUE(structure.intersect(Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2)}, record, scratch));
    EXPECT_EQ(record.t, 0.5);
    EXPECT_EQ(record.primitive, 0u);
    EXPECT_TRUE(structure.occluded(Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2), 0.5, 0.5}, scratch));
    EXPECT_FALSE(structure.occluded(
        Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2), 0.0, std::nextafter(0.5, 0.0)}, scratch));
    EXPECT_FALSE(structure.occluded(
        Ray{Point3(0.5, 0.5, -1), Vector3(0, 0, 2), std::nextafter(0.5, 1.0), kInfinity}, scratch));
    EXPECT_FALSE(structure.intersect(Ray{Point3(1.5, 1.5, -1), Vector3(0, 0, 1)}, record, scratch));
}

/// A structure over identical_triangles(copies): the tie goes to the lowest index, and
/// all_hits reports every copy exactly once (more copies than a mailbox has slots).
template <class Set>
void expect_identical_copies_each_once(const Accelerator<Set>& structure, std::size_t copies) {
    QueryScratch scratch;
    const Ray ray{Point3(0.2, 0.2, 5), Vector3(0, 0, -1)};
    HitRecord record;
    ASSERT_TRUE(structure.intersect(ray, record, scratch));
    EXPECT_EQ(record.primitive, 0u);
    std::vector<HitRecord> hits;
    structure.all_hits(ray, hits, scratch);
    ASSERT_EQ(hits.size(), copies);
    std::vector<bool> seen(copies, false);
    for (const HitRecord& hit : hits) seen[hit.primitive] = true;
    EXPECT_EQ(std::count(seen.begin(), seen.end(), true), static_cast<long>(copies));
}

/// Both twins of twin_triangles_across_a_cell_boundary (primitives 16 and 17) are brute force's
/// nearest hit on some of `rays`, or the case would test nothing.
template <class Set>
void expect_both_twins_win(const BruteForce<Set>& brute, const std::vector<Ray>& rays) {
    QueryScratch scratch;
    int far_wins = 0, near_wins = 0;
    for (const Ray& ray : rays) {
        HitRecord record;
        ASSERT_TRUE(brute.intersect(ray, record, scratch));
        far_wins += record.primitive == 16;
        near_wins += record.primitive == 17;
    }
    EXPECT_GT(far_wins, 0);
    EXPECT_GT(near_wins, 0);
}

/// make_accelerator(name, set, config) builds the structure `name` over `set`, with stats
/// that count every primitive at least once.
template <class Set>
void expect_factory_builds(std::string_view name, const Set& set, const AcceleratorConfig& config) {
    const auto structure = make_accelerator(name, set, config);
    EXPECT_EQ(structure->name(), name);
    const AcceleratorStats stats = structure->stats();
    EXPECT_EQ(stats.primitives, set.size());
    EXPECT_GT(stats.nodes, 0u);
    EXPECT_GE(stats.references, set.size());
    EXPECT_GT(stats.bytes, 0u);
    EXPECT_FALSE(stats.details.empty());
}

}  // namespace csgrt::test
