// Watertightness of every structure the factory registers (accelerator_names(), so new ones
// are covered as they are added), over float and double triangle sets of closed meshes: real
// ones (elephant, armadillo), in-code ones (integer cube, subdivided octahedron) and a Loop
// subdivision of 2,097,152 triangles. A ray that starts inside a closed surface must hit
// it; one that does not has escaped through a crack. Rays go in random directions and exactly
// at vertices and edge midpoints (the shared edges and vertices that a non-watertight test or
// a culling box without padding loses). Brute force is run on the small meshes only.
//
// Interior points are decided independently of csgrt: by the parity of the triangles CGAL's
// exact predicates say a ray from the point crosses (three directions must agree), and the
// point must stay inside when moved by 1e-4 of the mesh's size along each axis, so that
// rounding the origin to float cannot carry it outside.
//
// WatertightHeavy (10^6 rays per structure and precision, meshes up to 2,097,152 triangles)
// carries the ctest label "heavy": under the sanitizers it runs at test::test_scale() of its
// rays, on a Loop subdivision of 131,072 triangles (support/test_scale.h, docs/accuracy.md).

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/reference/cgal_reference.h"
#include "csgrt/accel/factory.h"
#include "csgrt/mesh/mesh_io.h"
#include "csgrt/mesh/mesh_tools.h"
#include "csgrt/accel/triangle_set.h"
#include "stress/stress_config.h"
#include "stress/summary.h"
#include "support/meshes.h"
#include "support/random.h"
#include "support/real_meshes.h"
#include "support/reference_check.h"
#include "support/test_scale.h"

namespace csgrt {
namespace {

struct ClosedMesh {
    std::string name;
    TriangleMeshData data;
    /// Brute force is run on it (a few hundred triangles).
    bool small = false;
};

TriangleMeshData from_test_mesh(const test::TestMesh& mesh) {
    TriangleMeshData data{mesh.vertices, mesh.triangles, {}};
    validate_mesh(data);
    return data;
}

/// The closed meshes, each loaded or built once per test program: the light set (two in-code
/// meshes for brute force, and the elephant) or the heavy one (the armadillo and a Loop
/// subdivision of 2,097,152 triangles, 131,072 at reduced scale; in the long run also the
/// bunny and 832,000 triangles of subdivided armadillo).
const std::vector<ClosedMesh>& closed_meshes(bool heavy) {
    auto real = [](const std::string& name, std::vector<ClosedMesh>& list) {
        const std::filesystem::path path = test::real_mesh(name);
        if (path.empty()) {
            std::printf("  (%s unavailable: data/fetch-meshes failed)\n", name.c_str());
            return;
        }
        MeshReport report;
        TriangleMeshData data = load_mesh(path, &report);
        if (!report.is_closed) ADD_FAILURE() << name << " is expected to be closed";
        list.push_back({name, std::move(data), false});
    };
    static const std::vector<ClosedMesh> light = [&] {
        std::vector<ClosedMesh> list;
        list.push_back({"integer_cube(6)", from_test_mesh(test::integer_cube(6)), true});
        list.push_back({"sphere_mesh(3)", from_test_mesh(test::sphere_mesh(3)), true});
        real("elephant", list);
        return list;
    }();
    static const std::vector<ClosedMesh> heavy_list = [&] {
        std::vector<ClosedMesh> list;
        real("armadillo", list);
        if (test::stress_multiplier() > 1) real("bunny00", list);
        // 512 * 4^6 = 2,097,152 triangles (the issue asks for meshes of up to 10^6); under the
        // sanitizers 512 * 4^4 = 131,072, which runs the same code in a sixteenth of the time.
        const TriangleMeshData octahedron = from_test_mesh(test::sphere_mesh(3));
        const int levels = test::reduced_scale() ? 4 : 6;
        list.push_back({"loop_subdivide(sphere_mesh(3), " + std::to_string(levels) + ")",
                        loop_subdivide(octahedron, levels), false});
        if (test::stress_multiplier() > 1) {
            for (const ClosedMesh& mesh : std::vector<ClosedMesh>(list)) {
                if (mesh.name == "armadillo") {
                    list.push_back(
                        {"loop_subdivide(armadillo, 2)", loop_subdivide(mesh.data, 2), false});
                }
            }
        }
        return list;
    }();
    return heavy ? heavy_list : light;
}

Aabb bounds_of(const TriangleMeshData& mesh) {
    Aabb box;
    for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
    return box;
}

/// Inside by the parity of exact crossings along three random rays, which must agree.
bool exactly_inside(const CgalReference& reference, const Point3& p, test::Random& random) {
    int votes = 0;
    for (int k = 0; k < 3; ++k) {
        const Ray ray{p, random.unit_vector()};
        votes += reference.intersected_primitives(ray).size() % 2;
    }
    return votes == 3;
}

/// Interior points of the mesh, representable in float (so the float and double tests start
/// from the same origin), at least 1e-4 sizes inside along each axis.
std::vector<Point3> interior_points(const TriangleSet<float>& set, const Aabb& box, int count,
                                    std::uint64_t seed) {
    const CgalReference reference(set);
    test::Random random(seed);
    const double margin = 1e-4 * box.diagonal().norm();
    std::vector<Point3> points;
    for (int attempt = 0; static_cast<int>(points.size()) < count && attempt < 100 * count;
         ++attempt) {
        const Point3 p = random.in_box(box).cast<float>().cast<double>();
        if (!exactly_inside(reference, p, random)) continue;
        bool deep = true;
        for (int axis = 0; axis < 3 && deep; ++axis) {
            for (const double side : {-1.0, 1.0}) {
                Point3 q = p;
                q[axis] += side * margin;
                deep = deep && exactly_inside(reference, q, random);
            }
        }
        if (deep) points.push_back(p);
    }
    return points;
}

struct Escapes {
    long rays = 0;
    long escapes = 0;
    long aimed_at_vertices = 0;
    long aimed_at_edges = 0;
};

/// Rays from the interior points: a third in random directions, a third exactly at a vertex,
/// a third exactly at the midpoint of an edge (exact in double for float corners).
template <class Real>
Escapes shoot(const Accelerator<TriangleSet<Real>>& structure, const TriangleSet<Real>& set,
              const std::vector<Point3>& origins, long rays, std::uint64_t seed,
              const std::string& label) {
    test::Random random(seed);
    QueryScratch scratch;
    Escapes tally;
    int reported = 0;
    for (long i = 0; i < rays; ++i) {
        Ray ray;
        ray.origin = origins[i % origins.size()];
        const std::size_t triangle =
            static_cast<std::size_t>(random.uniform(0.0, static_cast<double>(set.size()) - 0.5));
        const int corner = static_cast<int>(i / 3 % 3);
        const Point3 a = set.corner(triangle, corner).template cast<double>();
        const Point3 b = set.corner(triangle, (corner + 1) % 3).template cast<double>();
        switch (i % 3) {
            case 0:
                ray.direction = random.unit_vector() * random.uniform(0.25, 4.0);
                break;
            case 1:
                ray.direction = a - ray.origin;
                ++tally.aimed_at_vertices;
                break;
            default:
                ray.direction = 0.5 * (a + b) - ray.origin;
                ++tally.aimed_at_edges;
                break;
        }
        if (ray.direction.squaredNorm() == 0.0) continue;
        ++tally.rays;
        HitRecord record;
        const bool hit = structure.intersect(ray, record, scratch);
        const bool occluded = structure.occluded(ray, scratch);
        if (hit && occluded && record.t > 0.0) continue;
        ++tally.escapes;
        if (++reported <= 5) {
            ADD_FAILURE() << label << ": escape (hit " << hit << ", occluded " << occluded << ", t "
                          << record.t << ") Ray{Point3(" << ray.origin.x() << ", " << ray.origin.y()
                          << ", " << ray.origin.z() << "), Vector3(" << ray.direction.x() << ", "
                          << ray.direction.y() << ", " << ray.direction.z() << ")}";
        }
    }
    return tally;
}

/// Shoots `rays` rays per structure and precision, split over the large meshes (brute force
/// gets the small meshes only, `rays` / 4 each), from interior points: zero escapes.
void expect_no_escapes(const std::vector<ClosedMesh>& meshes, long rays) {
    const long multiplier = test::stress_multiplier();
    long large_meshes = 0;
    for (const ClosedMesh& mesh : meshes) large_meshes += mesh.small ? 0 : 1;
    std::printf(
        "\n  | mesh | triangles | structure | precision | rays | at vertices | at edges"
        " | escapes |\n");
    std::uint64_t seed = 900;
    for (const ClosedMesh& mesh : meshes) {
        const TriangleSet<float> float_set(mesh.data.vertices, mesh.data.triangles);
        const TriangleSet<double> double_set(mesh.data.vertices, mesh.data.triangles);
        const std::vector<Point3> origins =
            interior_points(float_set, bounds_of(mesh.data), 2000, ++seed);
        ASSERT_GE(origins.size(), 1000u) << mesh.name;
        for (const std::string_view name : accelerator_names()) {
            const bool brute = name == "brute";
            if (brute && !mesh.small) continue;
            const long count =
                multiplier * (mesh.small ? rays / 4 : rays / std::max(1L, large_meshes));
            const std::string label = mesh.name + " " + std::string(name);
            const auto float_structure = make_accelerator(name, float_set);
            const Escapes f =
                shoot(*float_structure, float_set, origins, count, ++seed, label + " float");
            const auto double_structure = make_accelerator(name, double_set);
            const Escapes d =
                shoot(*double_structure, double_set, origins, count, ++seed, label + " double");
            for (const auto& [precision, tally] : {std::pair{"float", f}, std::pair{"double", d}}) {
                std::printf("  | %s | %zu | %s | %s | %ld | %ld | %ld | %ld |\n", mesh.name.c_str(),
                            mesh.data.triangles.size(), std::string(name).c_str(), precision,
                            tally.rays, tally.aimed_at_vertices, tally.aimed_at_edges,
                            tally.escapes);
                EXPECT_EQ(tally.escapes, 0) << label << " " << precision;
                test::summarize(label + " " + precision, tally.rays, tally.escapes);
            }
        }
    }
}

TEST(Watertight, NoRayFromInsideAClosedMeshEscapesAnyStructure) {
    // 10^5 rays per structure and precision (label "heavy": test::scaled() of it under the
    // sanitizers, where the full count took a minute of CPU, the longest test of the asan run).
    expect_no_escapes(closed_meshes(false), test::scaled(100000L));
}

TEST(WatertightHeavy, MillionRaysFromInsideMeshesUpToAMillionTriangles) {
    // The scale: 10^6 rays per structure and precision, into meshes of up to
    // 2,097,152 triangles (label "heavy": test::scaled() of it under the sanitizers).
    expect_no_escapes(closed_meshes(true), test::scaled(1000000L));
}

TEST(Watertight, IntegerCubeFromHalfIntegerPointsAtEveryVertexAndEdge) {
    // Everything exact: origins at half-integer points inside [0, 6]^3, targets at every
    // vertex and every edge midpoint of the cube's surface grid (integers and half-integers),
    // so the direction is exact and the ray passes exactly through the vertex or edge.
    const test::TestMesh cube = test::integer_cube(6);
    const TriangleSet<float> float_set(cube.vertices, cube.triangles);
    const TriangleSet<double> double_set(cube.vertices, cube.triangles);
    std::vector<Point3> targets;
    for (const auto& triangle : cube.triangles) {
        for (int k = 0; k < 3; ++k) {
            const Point3 a = cube.vertices[triangle[k]], b = cube.vertices[triangle[(k + 1) % 3]];
            targets.push_back(a);
            targets.push_back(0.5 * (a + b));
        }
    }
    const std::vector<Point3> origins = {Point3(0.5, 0.5, 0.5), Point3(3, 3, 3),
                                         Point3(5.5, 2.5, 0.5), Point3(1.5, 4.5, 3.5),
                                         Point3(2.5, 0.5, 5.5)};
    for (const std::string_view name : accelerator_names()) {
        const auto float_structure = make_accelerator(name, float_set);
        const auto double_structure = make_accelerator(name, double_set);
        QueryScratch scratch;
        long escapes = 0, rays = 0;
        for (const Point3& origin : origins) {
            for (const Point3& target : targets) {
                const Ray ray{origin, target - origin};
                HitRecord record;
                for (const bool hit : {float_structure->intersect(ray, record, scratch),
                                       double_structure->intersect(ray, record, scratch),
                                       float_structure->occluded(ray, scratch),
                                       double_structure->occluded(ray, scratch)}) {
                    ++rays;
                    escapes += hit ? 0 : 1;
                }
            }
        }
        EXPECT_EQ(escapes, 0) << name << " over " << rays << " queries";
        test::summarize("integer_cube(6) " + std::string(name) + " vertices and edges", rays,
                        escapes);
    }
}

TEST(Watertight, OpenDragonAgreesWithExactPredicatesAtVerticesAndEdges) {
    // ChineseDragon-10kv is open (boundary edges), so rays from inside are not defined; on it
    // every structure must agree with CGAL's exact predicates on rays aimed at vertices and
    // edge midpoints, outside the ambiguity band of support/reference_check.h.
    const std::filesystem::path path = test::real_mesh("ChineseDragon-10kv");
    if (path.empty()) GTEST_SKIP() << "data/fetch-meshes could not provide the dragon";
    const TriangleMeshData mesh = load_mesh(path);
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    const CgalReference reference(set);
    const Aabb box = bounds_of(mesh);
    // CGAL answers each ray once; every structure is judged against those answers.
    const int count = test::scaled(20000) * test::stress_multiplier();
    test::Random random(77);
    std::vector<Ray> rays;
    for (int i = 0; i < count; ++i) {
        Ray ray = random.ray_between(test::enlarged(box, 1.0), box);
        const std::size_t triangle =
            static_cast<std::size_t>(random.uniform(0.0, static_cast<double>(set.size()) - 0.5));
        const Point3 a = set.corner(triangle, i % 3).cast<double>();
        const Point3 b = set.corner(triangle, (i + 1) % 3).cast<double>();
        ray.direction = (i % 2 ? a : 0.5 * (a + b)) - ray.origin;
        rays.push_back(ray);
    }
    const test::ReferenceAnswers answers(reference, std::move(rays));
    for (const std::string_view name : accelerator_names()) {
        // Brute force tests 20,000 triangles a ray: a tenth of the rays.
        const int structure_rays = name == "brute" ? count / 10 : count;
        const auto structure = make_accelerator(name, set);
        QueryScratch scratch;
        test::ReferenceTally tally;
        for (int i = 0; i < structure_rays; ++i) {
            HitRecord record;
            const bool hit = structure->intersect(answers.rays[i], record, scratch);
            test::judge_against_reference(set, reference, answers.rays[i], hit, record,
                                          answers.exact[i], tally);
        }
        tally.print("dragon " + std::string(name) + " float");
        EXPECT_EQ(tally.disagreements(), 0) << name;
        test::summarize("dragon " + std::string(name) + " float vs CGAL", tally.rays,
                        tally.disagreements(), tally.max_relative_error, "rel t");
        EXPECT_GT(tally.hits, structure_rays / 2) << name;
    }
}

}  // namespace
}  // namespace csgrt
