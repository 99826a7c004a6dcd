// Every structure the factory registers (brute, grid, hgrid, rayclass, bvh), in float and in
// double, ray by ray against CGAL's exact predicates and bit for bit against brute force, on
// three real meshes; and every structure against brute force on a list of 10,000 shapes.
//
// CGAL answers each ray once. The meshes' vertices are rounded to float first, so the float
// and the double triangle set hold the very same corners, and one exact answer per ray serves
// all ten structure-precision pairs (the double set then tests double arithmetic on
// float-representable corners; grid_agreement_test.cpp and the watertight tests cover
// irrational double corners). Brute force, the costly query on these meshes, also answers
// each ray once per precision for the four other structures.

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cctype>
#include <cstdio>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "csgrt/accel/brute_force.h"
#include "csgrt/accel/factory.h"
#include "csgrt/accel/shape_set.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/sphere.h"
#include "csgrt/mesh/mesh_io.h"
#include "csgrt/reference/cgal_reference.h"
#include "support/meshes.h"
#include "support/random.h"
#include "support/rays.h"
#include "support/real_meshes.h"
#include "support/reference_check.h"
#include "support/test_scale.h"
#include "support/unbounded_plane.h"

namespace csgrt {
namespace {

struct RealMesh {
    const char* name;
    std::size_t triangles;
    /// Camera-like rays, and as many incoherent ones: fewer on the larger meshes, where brute
    /// force tests every triangle for every ray.
    int rays_per_kind;
};

/// GoogleTest prints the parameter into the test's ctest name: the mesh's name, not its bytes.
void PrintTo(const RealMesh& mesh, std::ostream* out) {
    *out << mesh.name;
}

constexpr std::array<RealMesh, 3> kRealMeshes = {
    {{"armadillo", 52000, 5000}, {"ChineseDragon-10kv", 19994, 10000}, {"elephant", 5558, 35000}}};

constexpr int rays_over_all_meshes() {
    int rays = 0;
    for (const RealMesh& mesh : kRealMeshes) rays += 2 * mesh.rays_per_kind;
    return rays;
}
// The count, per structure and precision, at full size (the release build); the
// sanitizer build runs test::scaled() of each mesh's rays (support/test_scale.h).
static_assert(rays_over_all_meshes() >= 100000);

/// Bit-level equality of two answers: hit or miss, the same primitive, t, u and v.
bool same_answer(bool hit_a, const HitRecord& a, bool hit_b, const HitRecord& b) {
    if (hit_a != hit_b) return false;
    return !hit_a ||
           (std::bit_cast<std::uint64_t>(a.t) == std::bit_cast<std::uint64_t>(b.t) &&
            a.primitive == b.primitive && a.object == b.object && a.u == b.u && a.v == b.v);
}

/// Every structure over `set` on every ray of `answers`: judged against CGAL's answer
/// (support/reference_check.h: hit or miss, the nearest primitive, and t to the ambiguity band
/// of 64 roundoffs of Real stretched by 1 / |cos| of the incidence angle; rays inside the band
/// are counted and printed, any disagreement outside it fails), and the four other than brute
/// force bit for bit against brute force's answer, with occluded equal to it too.
///
/// `along_faces`: the rays run along faces and edges (axis rays on an integer mesh), where hits
/// on another triangle must still have the reference's t (judge_against_reference's
/// t_must_agree) and many rays touch triangles only on their boundary, where the watertight
/// test's tie rule may give the touch to none of them (ambiguous, counted).
template <class Real>
void expect_every_structure_agrees(const TriangleSet<Real>& set, const CgalReference& reference,
                                   const test::ReferenceAnswers& answers, const std::string& label,
                                   bool along_faces = false) {
    using Set = TriangleSet<Real>;
    BruteForce<Set> brute;
    brute.build(set);
    std::vector<std::unique_ptr<Accelerator<Set>>> others;
    for (const std::string_view name : accelerator_names()) {
        if (name != "brute") others.push_back(make_accelerator(name, set));
    }
    ASSERT_EQ(others.size(), 4u) << "a new structure? it is compared here automatically";
    std::vector<test::ReferenceTally> tallies(1 + others.size());
    std::vector<long> differences(others.size(), 0);
    QueryScratch scratch;
    for (std::size_t i = 0; i < answers.rays.size(); ++i) {
        const Ray& ray = answers.rays[i];
        HitRecord expected;
        const bool expected_hit = brute.intersect(ray, expected, scratch);
        test::judge_against_reference(set, reference, ray, expected_hit, expected, answers.exact[i],
                                      tallies[0], along_faces);
        for (std::size_t k = 0; k < others.size(); ++k) {
            HitRecord actual;
            const bool hit = others[k]->intersect(ray, actual, scratch);
            test::judge_against_reference(set, reference, ray, hit, actual, answers.exact[i],
                                          tallies[k + 1], along_faces);
            const bool occluded = others[k]->occluded(ray, scratch);
            if (same_answer(hit, actual, expected_hit, expected) && occluded == expected_hit)
                continue;
            if (++differences[k] <= 3) {
                ADD_FAILURE() << label << " " << others[k]->name() << " ray " << i << " o ("
                              << ray.origin.transpose() << ") d (" << ray.direction.transpose()
                              << ") [" << ray.t_min << ", " << ray.t_max << "]: brute force "
                              << expected_hit << " t " << expected.t << " primitive "
                              << expected.primitive << "; structure " << hit << " t " << actual.t
                              << " primitive " << actual.primitive << ", occluded " << occluded;
            }
        }
    }
    for (std::size_t k = 0; k < tallies.size(); ++k) {
        const std::string name(k == 0 ? brute.name() : others[k - 1]->name());
        const test::ReferenceTally& tally = tallies[k];
        tally.print(label + " " + name);
        EXPECT_EQ(tally.rays, static_cast<long>(answers.rays.size())) << name;
        EXPECT_EQ(tally.disagreements(), 0) << label << " " << name;
        // Camera rays aim at the mesh's box and half the incoherent ones start inside it:
        // measured 26% (elephant) to 43% (dragon) hits; a structure that lost triangles would
        // fall far below a fifth.
        EXPECT_GT(tally.hits, tally.rays / 5) << label << " " << name;
        // Ambiguous rays pass within 64 roundoffs of an edge: random rays rarely do; of the
        // rays along faces and edges (two thirds of them), fewer than half.
        EXPECT_LT(tally.ambiguous, tally.rays / (along_faces ? 3 : 200)) << label << " " << name;
        if (k > 0) {
            EXPECT_EQ(differences[k - 1], 0) << label << " " << name;
        }
    }
}

class StructuresAgainstCgal : public ::testing::TestWithParam<RealMesh> {};

TEST_P(StructuresAgainstCgal, EveryStructureAndPrecisionRayByRay) {
    const RealMesh& param = GetParam();
    const std::filesystem::path path = test::real_mesh(param.name);
    if (path.empty()) GTEST_SKIP() << "data/fetch-meshes could not provide " << param.name;
    TriangleMeshData mesh = load_mesh(path);
    ASSERT_EQ(mesh.triangles.size(), param.triangles);
    for (Eigen::Vector3d& vertex : mesh.vertices) vertex = vertex.cast<float>().cast<double>();
    const TriangleSet<float> float_set(mesh.vertices, mesh.triangles);
    const TriangleSet<double> double_set(mesh.vertices, mesh.triangles);
    for (std::size_t i = 0; i < float_set.size(); ++i) {
        for (int k = 0; k < 3; ++k)
            ASSERT_EQ(float_set.corner(i, k).cast<double>(), double_set.corner(i, k));
    }
    const CgalReference reference(double_set);

    const Aabb box = test::bounds_of(mesh.vertices);
    const int per_kind = test::scaled(param.rays_per_kind);
    std::vector<Ray> rays = test::camera_rays(box, per_kind, 301);
    const std::vector<Ray> incoherent = test::incoherent_rays(box, per_kind, 302);
    rays.insert(rays.end(), incoherent.begin(), incoherent.end());
    test::bound_for_reference(rays, box);
    const test::ReferenceAnswers answers(reference, std::move(rays));
    ASSERT_EQ(answers.rays.size(), 2u * static_cast<std::size_t>(per_kind));

    expect_every_structure_agrees(float_set, reference, answers,
                                  std::string(param.name) + " float");
    expect_every_structure_agrees(double_set, reference, answers,
                                  std::string(param.name) + " double");
}

INSTANTIATE_TEST_SUITE_P(RealMeshes, StructuresAgainstCgal, ::testing::ValuesIn(kRealMeshes),
                         [](const ::testing::TestParamInfo<RealMesh>& info) {
                             std::string name = info.param.name;
                             for (char& c : name) {
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             }
                             return name;
                         });

/// Closed meshes with integer (or float-exact) coordinates and axis-aligned faces: the integer
/// cube, and three cubes that share faces (two side by side, one on top across their seam, so
/// its bottom face's edges run inside the others' top faces), also scaled by 3/8 and moved to
/// (1024, -2048, 512).
std::vector<std::pair<std::string, test::TestMesh>> meshes_with_axis_faces() {
    auto joined = [](const std::vector<std::pair<test::TestMesh, Vector3>>& parts, double scale,
                     const Vector3& offset) {
        test::TestMesh mesh;
        for (const auto& [part, shift] : parts) {
            const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
            for (const Eigen::Vector3d& v : part.vertices)
                mesh.vertices.push_back(offset + scale * (v + shift));
            for (const auto& t : part.triangles)
                mesh.triangles.push_back({first + t[0], first + t[1], first + t[2]});
        }
        return mesh;
    };
    const std::vector<std::pair<test::TestMesh, Vector3>> cubes = {
        {test::integer_cube(3), Vector3(0, 0, 0)},
        {test::integer_cube(3), Vector3(3, 0, 0)},
        {test::integer_cube(2), Vector3(1.5, 3, 0.5)}};
    return {{"integer cube [0,6]^3", test::integer_cube(6)},
            {"three cubes sharing faces", joined(cubes, 1.0, Vector3::Zero())},
            {"three cubes x 3/8 at (1024, -2048, 512)",
             joined(cubes, 0.375, Vector3(1024, -2048, 512))}};
}

TEST(StructuresAlongFaces, AxisRaysAlongFacesAndEdgesAgainstCgalAndBruteForce) {
    // The rerun the exact in-plane reference asked for (tests/accel/in_plane_reference_test.cpp
    // has the hand-worked distances): every structure and precision on axis rays along the
    // faces and edges of meshes where they are common, against CGAL's exact answer (t to the
    // band even where another triangle is named) and bit for bit against brute force. The
    // coordinates are float-exact, so both precisions hold the same corners.
    for (const auto& [name, mesh] : meshes_with_axis_faces()) {
        const TriangleSet<float> float_set(mesh.vertices, mesh.triangles);
        const TriangleSet<double> double_set(mesh.vertices, mesh.triangles);
        const CgalReference reference(double_set);
        const Aabb box = test::mesh_bounds(mesh);
        std::vector<Ray> rays;
        test::Random random(1616);
        test::append_rays_along_faces_and_edges(random, box, test::axis_coordinates(mesh.vertices),
                                                test::scaled(6000), rays);
        const test::ReferenceAnswers answers(reference, std::move(rays));
        expect_every_structure_agrees(float_set, reference, answers, name + " float", true);
        expect_every_structure_agrees(double_set, reference, answers, name + " double", true);
    }
}

TEST(StructuresAgainstBruteForce, TenThousandSpheresAndAnUnboundedPlane) {
    // A list of 10,001 shapes: spheres of radius 0.02 to 0.4 (some overlapping) above an
    // unbounded plane. Brute force, which calls every shape, answers each ray once; the other
    // structures must return its answer bit for bit (the set's tie rule makes the nearest hit
    // unique), and occluded must agree. Label "heavy": test::scaled() of the rays under the
    // sanitizers.
    constexpr int kSpheres = 10000;
    const int rays_per_kind = test::scaled(10000);
    test::Random random(1500);
    std::vector<std::shared_ptr<const Shape>> shapes;
    const Aabb region(Point3(-10, -10, 1), Point3(10, 10, 21));
    for (int i = 0; i < kSpheres; ++i)
        shapes.push_back(
            std::make_shared<Sphere>(random.in_box(region), random.uniform(0.02, 0.4)));
    shapes.push_back(std::make_shared<test::UnboundedPlane>());
    const ShapeSet set(shapes);
    BruteForce<ShapeSet> brute;
    brute.build(set);
    std::vector<std::unique_ptr<Accelerator<ShapeSet>>> others;
    for (const std::string_view name : accelerator_names()) {
        if (name != "brute") others.push_back(make_accelerator(name, set));
    }
    const Aabb box(Point3(-10, -10, 0), Point3(10, 10, 21));
    std::vector<Ray> rays = test::camera_rays(box, rays_per_kind, 1501);
    const std::vector<Ray> incoherent = test::incoherent_rays(box, rays_per_kind, 1502);
    rays.insert(rays.end(), incoherent.begin(), incoherent.end());
    QueryScratch scratch;
    long hits = 0, plane_hits = 0;
    std::vector<long> differences(others.size(), 0);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        HitRecord expected;
        const bool expected_hit = brute.intersect(rays[i], expected, scratch);
        hits += expected_hit;
        plane_hits += expected_hit && expected.object == kSpheres;
        for (std::size_t k = 0; k < others.size(); ++k) {
            HitRecord actual;
            const bool hit = others[k]->intersect(rays[i], actual, scratch);
            const bool occluded = others[k]->occluded(rays[i], scratch);
            if (same_answer(hit, actual, expected_hit, expected) && occluded == expected_hit &&
                (!hit || actual.shape == expected.shape))
                continue;
            if (++differences[k] <= 3) {
                ADD_FAILURE() << others[k]->name() << " ray " << i << ": brute force "
                              << expected_hit << " t " << expected.t << " object "
                              << expected.object << "; structure " << hit << " t " << actual.t
                              << " object " << actual.object << ", occluded " << occluded;
            }
        }
    }
    std::printf("[brute force] 10,000 spheres and a plane: %zu rays, %ld hits (%ld on the plane)\n",
                rays.size(), hits, plane_hits);
    for (std::size_t k = 0; k < others.size(); ++k)
        EXPECT_EQ(differences[k], 0) << others[k]->name();
    // Measured: about half the rays hit, a fifth of those the plane below the spheres.
    EXPECT_GT(hits, static_cast<long>(rays.size()) / 4);
    EXPECT_GT(plane_hits, static_cast<long>(rays.size()) / 50);
}

}  // namespace
}  // namespace csgrt
