#include "csgrt/accel/bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>
#include <type_traits>

#include "accel/grid_test_common.h"
#include "csgrt/accel/brute_force.h"
#include "csgrt/accel/factory.h"
#include "csgrt/accel/triangle_set.h"
#include "csgrt/core/error.h"
#include "support/meshes.h"
#include "support/precisions.h"
#include "support/random.h"
#include "support/test_scale.h"

namespace csgrt {
namespace {

using test::TestMesh;

/// Bit-level equality of two records as the structure contract demands it: hit or miss, the
/// same primitive (or set member) and the very same t, u and v.
struct Answer {
    bool hit = false;
    std::uint64_t t_bits = 0;
    std::uint32_t primitive = kNoIndex;
    std::uint32_t object = kNoIndex;
    float u = 0.0f, v = 0.0f;

    static Answer of(bool hit, const HitRecord& record) {
        if (!hit) return {};
        return {true,
                std::bit_cast<std::uint64_t>(record.t),
                record.primitive,
                record.object,
                record.u,
                record.v};
    }
    bool operator==(const Answer&) const = default;
};

std::ostream& operator<<(std::ostream& out, const Answer& a) {
    if (!a.hit) return out << "miss";
    return out << "t=" << std::bit_cast<double>(a.t_bits) << " primitive=" << a.primitive
               << " object=" << a.object << " uv=(" << a.u << ", " << a.v << ")";
}

std::string describe(const Ray& ray) {
    std::ostringstream out;
    out.precision(17);
    out << "o=(" << ray.origin.transpose() << ") d=(" << ray.direction.transpose() << ") ["
        << ray.t_min << ", " << ray.t_max << "]";
    return out.str();
}

/// Rays from outside the box toward it (camera-like), rays from inside or around it in random
/// directions (incoherent), and a few with random sub-intervals, some starting below t = 0.
std::vector<Ray> mixed_rays(const Aabb& box, int count, std::uint64_t seed) {
    test::Random random(seed);
    std::vector<Ray> rays;
    rays.reserve(count);
    const Aabb around = test::enlarged(box, 1.0);
    const Aabb target = test::enlarged(box, 0.02);
    for (int i = 0; i < count; ++i) {
        Ray ray;
        switch (i % 4) {
            case 0:
            case 1:
                ray = random.ray_between(around, target);
                break;
            case 2:
                ray.origin = random.in_box(test::enlarged(box, 0.1));
                ray.direction = random.unit_vector() * random.uniform(0.25, 4.0);
                break;
            default: {
                ray = random.ray_between(around, target);
                const double length = around.diagonal().norm() / ray.direction.norm();
                double a = random.uniform(-0.5, 1.5) * length,
                       b = random.uniform(-0.5, 1.5) * length;
                ray.t_min = std::min(a, b);
                ray.t_max = std::max(a, b);
                break;
            }
        }
        rays.push_back(ray);
    }
    return rays;
}

/// Compares `structure` with `brute` on every ray: intersect (bit for bit), occluded ==
/// intersect, and the counted entry points agree with the uncounted ones. Returns the number
/// of rays that hit.
template <class Set>
int expect_same_answers(const Accelerator<Set>& structure, const Accelerator<Set>& brute,
                        const std::vector<Ray>& rays, const std::string& label) {
    QueryScratch scratch;
    int hits = 0, failures = 0;
    for (std::size_t i = 0; i < rays.size() && failures < 10; ++i) {
        const Ray& ray = rays[i];
        HitRecord expected_record, record, counted_record;
        const Answer expected =
            Answer::of(brute.intersect(ray, expected_record, scratch), expected_record);
        const Answer actual = Answer::of(structure.intersect(ray, record, scratch), record);
        TraversalCounters counters;
        const Answer counted = Answer::of(
            structure.intersect_counted(ray, counted_record, scratch, counters), counted_record);
        const bool occluded = structure.occluded(ray, scratch);
        const bool occluded_counted = structure.occluded_counted(ray, scratch, counters);
        hits += expected.hit;
        const bool ok = actual == expected && counted == expected && occluded == expected.hit &&
                        occluded_counted == expected.hit;
        if (!ok) {
            ++failures;
            ADD_FAILURE() << label << " ray " << i << ": " << describe(ray)
                          << "\n  brute force: " << expected << "\n  structure:   " << actual
                          << "\n  counted:     " << counted << "\n  occluded " << occluded
                          << ", counted " << occluded_counted;
        }
    }
    return hits;
}

/// A random soup of long, thin triangles crossing the unit cube in every direction.
TestMesh thin_triangle_soup(int count, std::uint64_t seed) {
    test::Random random(seed);
    TestMesh mesh;
    const Aabb cube(Point3(0, 0, 0), Point3(1, 1, 1));
    for (int i = 0; i < count; ++i) {
        const Point3 a = random.in_box(cube);
        const Point3 b = random.in_box(cube);
        const Point3 c = a + random.uniform(0.0, 0.03) * random.unit_vector();
        const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.insert(mesh.vertices.end(), {a, b, c});
        mesh.triangles.push_back({base, base + 1, base + 2});
    }
    return mesh;
}

/// "A teapot in a stadium": a small dense sphere mesh at the origin and a few huge triangles
/// (a floor and two walls) a thousand times larger around it.
TestMesh teapot_in_stadium() {
    TestMesh mesh = test::sphere_mesh(4);
    for (auto& vertex : mesh.vertices) vertex *= 0.1;
    const double s = 1000.0;
    const std::vector<Eigen::Vector3d> corners = {{-s, -1, -s}, {s, -1, -s}, {s, -1, s},
                                                  {-s, -1, s},  {-s, s, -s}, {s, s, -s}};
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), corners.begin(), corners.end());
    for (std::array<std::uint32_t, 3> t :
         {std::array<std::uint32_t, 3>{0, 1, 2}, {0, 2, 3}, {0, 1, 5}, {0, 5, 4}}) {
        mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    }
    return mesh;
}

template <class Real>
class BvhMeshTest : public ::testing::Test {};
TYPED_TEST_SUITE(BvhMeshTest, test::Precisions);

TYPED_TEST(BvhMeshTest, SameHitsAsBruteForceOnEveryMeshAndLayout) {
    // The tie rule makes the nearest hit independent of test order, so the BVH must return
    // exactly BruteForce's primitive and t: any difference is a culled primitive (a box that
    // was not conservative) or a traversal that stopped too early.
    struct Case {
        std::string name;
        TestMesh mesh;
        int rays;
    };
    // Label "heavy": test::scaled() of the rays under the sanitizers.
    std::vector<Case> cases;
    cases.push_back({"integer_cube(8)", test::integer_cube(8), test::scaled(40000)});
    cases.push_back({"sphere_mesh(5)", test::sphere_mesh(5), test::scaled(20000)});
    cases.push_back({"thin soup", thin_triangle_soup(4000, 7), test::scaled(20000)});
    cases.push_back({"teapot in stadium", teapot_in_stadium(), test::scaled(20000)});
    int total_rays = 0;
    for (const Case& c : cases) {
        const TriangleSet<TypeParam> set(c.mesh.vertices, c.mesh.triangles);
        // Box culling only makes the oracle faster: its double-precision box test (Aabb) is
        // independent of the BVH's float one, and it returns what the plain loop returns.
        BruteForce<TriangleSet<TypeParam>> brute;
        brute.build(set, BruteForceConfig{.box_culling = true});
        Aabb box = test::mesh_bounds(c.mesh);
        // In the stadium, aim at the teapot: that is where the cost and the precision are.
        if (c.name == "teapot in stadium")
            box = Aabb(Point3(-0.2, -0.2, -0.2), Point3(0.2, 0.2, 0.2));
        const std::vector<Ray> rays = mixed_rays(box, c.rays, 100 + total_rays);
        // The default (8-wide, triangle blocks for float sets, AVX2 where the CPU has it) on
        // every ray; the other layouts and code paths share most of their logic with it, so
        // a quarter of the rays suffice for each.
        const std::vector<std::pair<std::string, BvhConfig>> configs = {
            {"default", BvhConfig{}},
            {"width 8 SSE", BvhConfig{.avx2 = false}},
            {"width 8 without blocks", BvhConfig{.triangle_blocks = false}},
            {"width 4", BvhConfig{.width = 4}},
            {"width 4 without blocks", BvhConfig{.width = 4, .triangle_blocks = false}},
            {"width 2", BvhConfig{.width = 2}},
            {"width 2 without blocks", BvhConfig{.width = 2, .triangle_blocks = false}}};
        for (const auto& [name, config] : configs) {
            Bvh<TriangleSet<TypeParam>> bvh;
            bvh.build(set, config);
            const bool all = name == "default";
            const std::vector<Ray> subset(rays.begin(), rays.begin() + (all ? c.rays : c.rays / 4));
            const int hits = expect_same_answers<TriangleSet<TypeParam>>(bvh, brute, subset,
                                                                         c.name + " " + name);
            // A meaningful share of the rays must hit, or the comparison proves little.
            EXPECT_GT(hits, static_cast<int>(subset.size()) / 5) << c.name;
            if (all) total_rays += static_cast<int>(subset.size());
        }
    }
    EXPECT_GE(total_rays, test::scaled(100000));
}

/// A pinhole camera's rays: from a point outside the box through a width x width grid over the
/// box's middle, row by row, as neighbouring pixels' rays (coherent, the packets' case).
std::vector<Ray> camera_grid(const Aabb& box, int width) {
    const Vector3 diagonal = box.diagonal();
    const Point3 eye = box.center() + 1.5 * diagonal.norm() * Vector3(0.3, 0.25, 1.0).normalized();
    std::vector<Ray> rays;
    for (int y = 0; y < width; ++y) {
        for (int x = 0; x < width; ++x) {
            const Point3 target =
                box.lower + Vector3((x + 0.5) / width * diagonal.x(),
                                    (y + 0.5) / width * diagonal.y(), 0.5 * diagonal.z());
            Ray ray;
            ray.origin = eye;
            ray.direction = target - eye;
            rays.push_back(ray);
        }
    }
    return rays;
}

TYPED_TEST(BvhMeshTest, PacketsGiveTheSingleRayAnswersBitForBit) {
    // The packet traversal tests each ray against exactly the nodes and leaves its own
    // traversal may need, in another order; the tie rule makes the nearest hit independent of
    // the order, so intersect_packets must return intersect's very bits ray by ray, and both
    // BruteForce's (the independent answer). Ray counts are not multiples of the packet size,
    // and invalid rays sit among valid ones.
    struct Case {
        std::string name;
        TestMesh mesh;
    };
    std::vector<Case> cases;
    cases.push_back({"integer_cube(8)", test::integer_cube(8)});
    cases.push_back({"sphere_mesh(5)", test::sphere_mesh(5)});
    cases.push_back({"thin soup", thin_triangle_soup(4000, 7)});
    cases.push_back({"teapot in stadium", teapot_in_stadium()});
    const std::vector<std::pair<std::string, BvhConfig>> configs = {
        {"default", BvhConfig{}},
        {"width 8 SSE", BvhConfig{.avx2 = false}},
        {"width 8 without blocks", BvhConfig{.triangle_blocks = false}},
        {"width 4", BvhConfig{.width = 4}},
        {"width 2", BvhConfig{.width = 2}}};
    QueryScratch scratch;
    for (const Case& c : cases) {
        const TriangleSet<TypeParam> set(c.mesh.vertices, c.mesh.triangles);
        BruteForce<TriangleSet<TypeParam>> brute;
        brute.build(set, BruteForceConfig{.box_culling = true});
        const Aabb box = c.name == "teapot in stadium"
                             ? Aabb(Point3(-0.2, -0.2, -0.2), Point3(0.2, 0.2, 0.2))
                             : test::mesh_bounds(c.mesh);
        std::vector<Ray> rays = camera_grid(box, 45);
        if (c.name == "integer_cube(8)") {
            // One origin's rays exactly through the face z = 0's vertices, the midpoints of its
            // edges and of its quads' diagonals: d_z = 8 makes the shear exact, so the sheared
            // target is (0, 0) and an edge function of every triangle around it is exactly
            // zero (the case hit_sheared redoes in double). All directions positive, one test
            // axis: the packets take the ray-parallel leaf test.
            for (int j = 1; j <= 8; ++j) {
                for (int i = 1; i <= 8; ++i) {
                    for (const Vector3& offset :
                         {Vector3(0.0, 0.0, 0.0), Vector3(0.5, 0.0, 0.0), Vector3(0.5, 0.5, 0.0)}) {
                        Ray ray;
                        ray.origin = Point3(0.5, 0.5, -8.0);
                        ray.direction = Point3(i, j, 0.0) + offset - ray.origin;
                        if (ray.direction.x() < 8.0 && ray.direction.y() < 8.0) rays.push_back(ray);
                    }
                }
            }
        }
        // One origin's rays whose largest direction component changes from one to the next
        // (the triangle test's axes differ within a packet), ties included; eight from a
        // multiple of eight, so they make packets of their own.
        while (rays.size() % 8 != 0) rays.push_back(rays.front());
        for (int k = 0; k < 64; ++k) {
            Ray ray;
            ray.origin = box.lower - 0.5 * box.diagonal();
            const double step = 0.25 * (k % 8 - 4) / 4.0;
            ray.direction =
                k % 16 < 8 ? Vector3(1.0, 1.0 + step, 0.9) : Vector3(1.0, 0.9, 1.0 + step);
            rays.push_back(ray);
        }
        const std::vector<Ray> mixed = mixed_rays(box, test::scaled(3001), 77);
        rays.insert(rays.end(), mixed.begin(), mixed.end());
        for (std::size_t i = 5; i < rays.size(); i += 97) {
            rays[i].direction = Vector3(std::numeric_limits<double>::quiet_NaN(), 0.0, 1.0);
        }
        std::vector<Answer> expected(rays.size());
        int hits = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            HitRecord record;
            expected[i] = Answer::of(brute.intersect(rays[i], record, scratch), record);
            hits += expected[i].hit;
        }
        EXPECT_GT(hits, static_cast<int>(rays.size()) / 5) << c.name;
        for (const auto& [name, config] : configs) {
            Bvh<TriangleSet<TypeParam>> bvh;
            bvh.build(set, config);
            // A miss leaves its record as it was: fill them with a sentinel first.
            HitRecord sentinel;
            sentinel.t = -7.0;
            sentinel.primitive = 12345;
            std::vector<HitRecord> records(rays.size(), sentinel);
            std::unique_ptr<bool[]> hit(new bool[rays.size()]);
            std::unique_ptr<bool[]> occluded(new bool[rays.size()]);
            const std::size_t count =
                bvh.intersect_packets(rays, records, {hit.get(), rays.size()}, scratch);
            const std::size_t occluded_count =
                bvh.occluded_packets(rays, {occluded.get(), rays.size()}, scratch);
            EXPECT_EQ(count, static_cast<std::size_t>(hits)) << c.name << " " << name;
            EXPECT_EQ(occluded_count, static_cast<std::size_t>(hits)) << c.name << " " << name;
            int failures = 0;
            for (std::size_t i = 0; i < rays.size() && failures < 10; ++i) {
                HitRecord single_record;
                const Answer single =
                    Answer::of(bvh.intersect(rays[i], single_record, scratch), single_record);
                const Answer packet = Answer::of(hit[i], records[i]);
                const bool left = hit[i] || (records[i].t == -7.0 && records[i].primitive == 12345);
                if (packet != single || packet != expected[i] || occluded[i] != expected[i].hit ||
                    !left) {
                    ++failures;
                    ADD_FAILURE() << c.name << " " << name << " ray " << i << ": "
                                  << describe(rays[i]) << "\n  brute force: " << expected[i]
                                  << "\n  single ray:  " << single << "\n  packet:      "
                                  << packet << "\n  occluded " << occluded[i];
                }
            }
        }
    }
}

TEST(Bvh, PacketSpansOfDifferentSizesThrow) {
    const test::BuiltMesh<float, Bvh> built(test::sphere_mesh(2));
    const Bvh<TriangleSet<float>>& bvh = built.structure;
    QueryScratch scratch;
    const std::vector<Ray> rays(3);
    std::vector<HitRecord> records(2);
    bool hit[3], occluded[2];
    EXPECT_THROW(bvh.intersect_packets(rays, records, hit, scratch), InvalidParameter);
    records.resize(3);
    EXPECT_THROW(bvh.intersect_packets(rays, records, {hit, 2}, scratch), InvalidParameter);
    EXPECT_THROW(bvh.occluded_packets(rays, occluded, scratch), InvalidParameter);
    // An unbuilt tree answers every ray with a miss, as intersect does.
    const Bvh<TriangleSet<float>> unbuilt;
    EXPECT_EQ(unbuilt.intersect_packets(rays, records, hit, scratch), 0u);
}

TYPED_TEST(BvhMeshTest, AllHitsEqualBruteForceAsASet) {
    const Aabb teapot(Point3(-0.1, -0.1, -0.1), Point3(0.1, 0.1, 0.1));
    for (const auto& [mesh, box] :
         {std::pair{test::integer_cube(4), Aabb(Point3(0, 0, 0), Point3(4, 4, 4))},
          std::pair{teapot_in_stadium(), teapot}}) {
        const TriangleSet<TypeParam> set(mesh.vertices, mesh.triangles);
        BruteForce<TriangleSet<TypeParam>> brute;
        brute.build(set);
        std::vector<Ray> rays = mixed_rays(box, 4000, 31);
        // Whole lines, as CSG asks for them.
        for (std::size_t i = 0; i < rays.size(); i += 3) {
            rays[i].t_min = -kInfinity;
            rays[i].t_max = kInfinity;
        }
        for (const BvhConfig& config :
             {BvhConfig{}, BvhConfig{.avx2 = false}, BvhConfig{.triangle_blocks = false},
              BvhConfig{.width = 4}, BvhConfig{.width = 2}}) {
            Bvh<TriangleSet<TypeParam>> bvh;
            bvh.build(set, config);
            QueryScratch scratch;
            std::size_t total = 0;
            for (const Ray& ray : rays) {
                std::vector<HitRecord> expected, actual;
                brute.all_hits(ray, expected, scratch);
                bvh.all_hits(ray, actual, scratch);
                auto key = [](const HitRecord& r) {
                    return std::tuple(r.primitive, std::bit_cast<std::uint64_t>(r.t), r.u, r.v);
                };
                std::multiset<decltype(key(expected[0]))> a, b;
                for (const auto& r : expected) a.insert(key(r));
                for (const auto& r : actual) b.insert(key(r));
                ASSERT_EQ(a, b) << describe(ray);
                total += expected.size();
            }
            // A closed mesh is crossed an even number of times by a whole line.
            EXPECT_GT(total, rays.size()) << "too few hits to prove anything";
        }
    }
}

TEST(Bvh, TriangleBlocksGiveTheScalarTestsBitsOnEdgeAndVertexRays) {
    // The SIMD leaves shear four triangles at once and hand each lane they keep to the set's
    // scalar test (TriangleSet::hit_sheared). A lane dropped that the scalar test would keep,
    // or a bit computed differently, shows up as a hit missing from all_hits or differing in
    // t, u or v. Whole lines report every triangle they cross, so all_hits compares the two
    // tests on every triangle the line meets. Rays aimed exactly at shared vertices and at
    // points of shared edges make the edge functions zero or tiny: the double-precision
    // recomputation and the sign rules are exercised there. A million rays (label "heavy":
    // test::scaled() of them under the sanitizers).
    TestMesh fan;
    fan.vertices.emplace_back(0.0, 0.0, 0.0);
    for (int k = 0; k < 12; ++k) {
        const double angle = 2.0 * std::acos(-1.0) * k / 12.0;
        fan.vertices.emplace_back(std::cos(angle), std::sin(angle), 0.3 * std::sin(3.0 * angle));
    }
    for (std::uint32_t k = 0; k < 12; ++k) fan.triangles.push_back({0, k + 1, (k + 1) % 12 + 1});
    // At a scale of 2^-64 the edge functions' products are denormal floats, with few bits
    // left: a float zero next to two non-zero values of mixed signs happens, and the exact
    // recomputation sometimes turns it into a hit. A SIMD leaf that dropped such lanes would
    // fail here (checked by breaking it on purpose).
    TestMesh tiny = thin_triangle_soup(300, 19);
    for (auto& vertex : tiny.vertices) vertex *= 0x1p-64;
    const std::vector<std::pair<std::string, TestMesh>> meshes = {
        {"integer_cube(3)", test::integer_cube(3)},
        {"sphere_mesh(2)", test::sphere_mesh(2)},
        {"fan", fan},
        {"soup at 2^-64", tiny}};
    test::Random random(17);
    const int rays_per_mesh = test::scaled(250000);
    for (const auto& [name, mesh] : meshes) {
        const TriangleSet<float> set(mesh.vertices, mesh.triangles);
        BruteForce<TriangleSet<float>> brute;
        brute.build(set);
        Bvh<TriangleSet<float>> avx2, sse;
        avx2.build(set);
        sse.build(set, BvhConfig{.avx2 = false});
        ASSERT_FALSE(avx2.leaf_triangles().empty());
        const Aabb box = test::mesh_bounds(mesh);
        QueryScratch scratch;
        int failures = 0;
        std::size_t total_hits = 0;
        for (int i = 0; i < rays_per_mesh && failures < 10; ++i) {
            Ray ray;
            ray.origin = random.in_box(test::enlarged(box, 0.5));
            const auto& triangle =
                mesh.triangles[random.integer(0, int(mesh.triangles.size()) - 1)];
            const Point3& a = mesh.vertices[triangle[random.integer(0, 2)]];
            const Point3& b = mesh.vertices[triangle[random.integer(0, 2)]];
            Point3 target;
            switch (i % 3) {
                case 0:  // a vertex, exactly
                    target = a;
                    break;
                case 1:  // a point of an edge (or of a vertex when a == b)
                    target = a + random.uniform() * (b - a);
                    break;
                default:
                    target = random.in_box(box);
                    break;
            }
            ray.direction = target - ray.origin;
            if (ray.direction.squaredNorm() == 0.0) continue;
            if (i % 2 == 0) {
                ray.t_min = -kInfinity;  // the whole line
            }
            std::vector<HitRecord> expected;
            brute.all_hits(ray, expected, scratch);
            total_hits += expected.size();
            auto key = [](const HitRecord& r) {
                return std::tuple(r.primitive, std::bit_cast<std::uint64_t>(r.t),
                                  std::bit_cast<std::uint32_t>(r.u),
                                  std::bit_cast<std::uint32_t>(r.v));
            };
            std::multiset<decltype(key(HitRecord{}))> want;
            for (const auto& r : expected) want.insert(key(r));
            HitRecord expected_record;
            const Answer expected_answer =
                Answer::of(brute.intersect(ray, expected_record, scratch), expected_record);
            for (const Bvh<TriangleSet<float>>* bvh : {&avx2, &sse}) {
                std::vector<HitRecord> actual;
                bvh->all_hits(ray, actual, scratch);
                std::multiset<decltype(key(HitRecord{}))> got;
                for (const auto& r : actual) got.insert(key(r));
                HitRecord record;
                const Answer answer = Answer::of(bvh->intersect(ray, record, scratch), record);
                if (got != want || answer != expected_answer ||
                    bvh->occluded(ray, scratch) != expected_answer.hit) {
                    ++failures;
                    ADD_FAILURE() << name << " ray " << i << " (" << (bvh == &sse ? "SSE" : "AVX2")
                                  << "): " << describe(ray) << "\n  all hits " << actual.size()
                                  << " against " << expected.size() << "; nearest " << answer
                                  << " against " << expected_answer;
                }
            }
        }
        // Lines through a closed mesh cross it at least twice; the fan and the soup are
        // crossed by most of the lines aimed at them.
        EXPECT_GT(total_hits, std::size_t(rays_per_mesh) / 2) << name;
    }
}

TEST(Bvh, Avx2AndSseTraversalsDoTheSameWorkRayByRay) {
    // Rays with a signed interval (t_min < 0) take the AVX2 node test that does the SSE test's
    // float operations in one 8-lane step, so both enter the same children at the same
    // distances: equal answers and equal counters, ray by ray. (On a CPU without AVX2 both run
    // the SSE code and the test proves nothing.) One difference is by design: the AVX2 leaf
    // tests a group of eight lanes in one step, so an occlusion query that the SSE leaf stops
    // after the group's first four has tested the other four too (at most 4 more triangles;
    // nearest-hit queries test every lane).
    //
    // The other rays take the fused node test (Avx2FusedNodeTest: one rounding per slab
    // distance instead of two, the slack at the entry end only), which can disagree with the
    // SSE test about a box, or about which of two children is nearer, only where the distances
    // involved lie within a few 2^-17 of each other relative to their size. Answers stay equal
    // ray by ray (both tests are conservative and the set's tie rule decides); the counters
    // may differ on such rays. With 30-40 boxes tested a ray at distances spread over the
    // ray's span, that is about 30 * 2^-16 = 5e-4 of the rays; at most 1% of them may differ,
    // and the totals within 0.1% of each other.
    const TestMesh mesh = test::sphere_mesh(5);
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    Bvh<TriangleSet<float>> avx2, sse;
    avx2.build(set);
    sse.build(set, BvhConfig{.avx2 = false});
    EXPECT_FALSE(sse.uses_avx2());
    if (!avx2.uses_avx2()) GTEST_SKIP() << "this CPU has no AVX2";
    QueryScratch scratch;
    int signed_rays = 0, fused_rays = 0, differing_rays = 0;
    std::size_t nodes_avx2 = 0, nodes_sse = 0, primitives_avx2 = 0, primitives_sse = 0;
    for (const Ray& ray : mixed_rays(test::mesh_bounds(mesh), 20000, 18)) {
        TraversalCounters a, b;
        HitRecord ra, rb;
        const Answer answer_a = Answer::of(avx2.intersect_counted(ray, ra, scratch, a), ra);
        const Answer answer_b = Answer::of(sse.intersect_counted(ray, rb, scratch, b), rb);
        ASSERT_EQ(answer_a, answer_b) << describe(ray);
        TraversalCounters c, d;
        ASSERT_EQ(avx2.occluded_counted(ray, scratch, c), sse.occluded_counted(ray, scratch, d))
            << describe(ray);
        if (!(ray.t_min >= 0.0)) {
            ++signed_rays;
            ASSERT_EQ(a.nodes_visited, b.nodes_visited) << describe(ray);
            ASSERT_EQ(a.boxes_tested, b.boxes_tested) << describe(ray);
            ASSERT_EQ(a.primitives_tested, b.primitives_tested) << describe(ray);
            ASSERT_EQ(c.nodes_visited, d.nodes_visited) << describe(ray);
            ASSERT_GE(c.primitives_tested, d.primitives_tested) << describe(ray);
            ASSERT_LE(c.primitives_tested, d.primitives_tested + 4) << describe(ray);
            continue;
        }
        ++fused_rays;
        if (a.nodes_visited != b.nodes_visited || a.primitives_tested != b.primitives_tested ||
            c.nodes_visited != d.nodes_visited) {
            ++differing_rays;
        }
        nodes_avx2 += a.nodes_visited + c.nodes_visited;
        nodes_sse += b.nodes_visited + d.nodes_visited;
        primitives_avx2 += a.primitives_tested;
        primitives_sse += b.primitives_tested;
    }
    EXPECT_GT(signed_rays, 1000);
    EXPECT_GT(fused_rays, 10000);
    EXPECT_LE(differing_rays, fused_rays / 100);
    EXPECT_NEAR(double(nodes_avx2), double(nodes_sse), 1e-3 * double(nodes_sse));
    EXPECT_NEAR(double(primitives_avx2), double(primitives_sse), 1e-3 * double(primitives_sse));
}

TEST(Bvh, EmptySetAndSinglePrimitive) {
    test::expect_empty_structure_answers_nothing<float, Bvh>();

    QueryScratch scratch;
    HitRecord record;
    const Ray ray{Point3(0, 0, -1), Vector3(0, 0, 1)};

    const std::vector<Eigen::Vector3d> vertices = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles = {{0, 1, 2}};
    const TriangleSet<float> one(vertices, triangles);
    for (int width : {2, 4, 8}) {
        Bvh<TriangleSet<float>> single;
        single.build(one, BvhConfig{.width = width});
        ASSERT_TRUE(single.intersect(ray, record, scratch));
        EXPECT_EQ(record.t, 1.0);
        EXPECT_EQ(record.primitive, 0u);
        EXPECT_TRUE(single.occluded(ray, scratch));
        // The interval is honoured at both ends, and closed.
        EXPECT_TRUE(single.occluded(Ray{ray.origin, ray.direction, 1.0, 1.0}, scratch));
        EXPECT_FALSE(single.occluded(Ray{ray.origin, ray.direction, 0.0, 0.999}, scratch));
        EXPECT_FALSE(single.occluded(Ray{ray.origin, ray.direction, 1.001, 5.0}, scratch));
        EXPECT_FALSE(single.intersect(Ray{Point3(3, 0, -1), Vector3(0, 0, 1)}, record, scratch));
    }
}

TEST(Bvh, IdenticalTrianglesShareOneLeafAndTiesGoToTheLowestIndex) {
    // Coincident centroids cannot be binned: the builder splits at the median while a node is
    // larger than max_leaf_size, and every answer is the lowest index.
    const std::vector<Eigen::Vector3d> vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const std::vector<std::array<std::uint32_t, 3>> triangles(1000, {0, 1, 2});
    const TriangleSet<float> set(vertices, triangles);
    BruteForce<TriangleSet<float>> brute;
    brute.build(set);
    for (int width : {2, 4, 8}) {
        Bvh<TriangleSet<float>> bvh;
        bvh.build(set, BvhConfig{.width = width});
        QueryScratch scratch;
        HitRecord record;
        ASSERT_TRUE(bvh.intersect(Ray{Point3(0.25, 0.25, 1), Vector3(0, 0, -1)}, record, scratch));
        EXPECT_EQ(record.primitive, 0u);
        std::vector<HitRecord> hits;
        bvh.all_hits(Ray{Point3(0.25, 0.25, 1), Vector3(0, 0, -1)}, hits, scratch);
        EXPECT_EQ(hits.size(), 1000u);
        expect_same_answers<TriangleSet<float>>(
            bvh, brute, mixed_rays(Aabb(Point3(0, 0, 0), Point3(1, 1, 0)), 2000, 8), "identical");
    }
}

TEST(Bvh, FlatMeshWithParallelAndGrazingRays) {
    // Every triangle in the plane z = 0: all boxes have zero thickness. Rays in the plane (the
    // slab test forms 0 * inf), rays grazing it, rays along the axes with +0 and -0 components.
    TestMesh mesh;
    for (int i = 0; i <= 20; ++i)
        for (int j = 0; j <= 20; ++j) mesh.vertices.emplace_back(i, j, 0.0);
    for (std::uint32_t i = 0; i < 20; ++i) {
        for (std::uint32_t j = 0; j < 20; ++j) {
            const std::uint32_t a = i * 21 + j, b = a + 21, c = b + 1, d = a + 1;
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
        }
    }
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    BruteForce<TriangleSet<float>> brute;
    brute.build(set);
    std::vector<Ray> rays;
    test::Random random(9);
    for (int i = 0; i < 4000; ++i) {
        const Point3 p(random.uniform(-2, 22), random.uniform(-2, 22), 0.0);
        const double angle = random.uniform(0, kTwoPi);
        rays.push_back(Ray{p, Vector3(std::cos(angle), std::sin(angle), 0.0)});   // in plane
        rays.push_back(Ray{p, Vector3(std::cos(angle), std::sin(angle), -0.0)});  // -0 z
        rays.push_back(Ray{p + Vector3(0, 0, 1e-7), Vector3(std::cos(angle), 0.3, -1e-6)});
        rays.push_back(Ray{Point3(p.x(), p.y(), 1), Vector3(0, 0, -1)});          // axis
        rays.push_back(Ray{Point3(p.x(), p.y(), -1), Vector3(0.0, -0.0, 2.0)});   // axis
        rays.push_back(Ray{Point3(std::round(p.x()), -1, 0), Vector3(0, 1, 0)});  // on edges
    }
    for (int width : {2, 4, 8}) {
        Bvh<TriangleSet<float>> bvh;
        bvh.build(set, BvhConfig{.width = width});
        const int hits = expect_same_answers<TriangleSet<float>>(bvh, brute, rays, "flat");
        EXPECT_GT(hits, 8000);
    }
}

TEST(Bvh, InvalidAndExtremeRays) {
    const test::BuiltMesh<double, Bvh> built(test::sphere_mesh(3));
    const auto& [set, brute, bvh] = built;
    QueryScratch scratch;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const Ray& ray :
         {Ray{Point3(nan, 0, 0), Vector3(1, 0, 0)}, Ray{Point3(0, 0, 0), Vector3(nan, 1, 0)},
          Ray{Point3(kInfinity, 0, 0), Vector3(-1, 0, 0)}, Ray{Point3(0, 0, 0), Vector3(0, 0, 0)},
          Ray{Point3(0, 0, 0), Vector3(kInfinity, 0, 0)},
          Ray{Point3(0, 0, 0), Vector3(1, 0, 0), 2.0, 1.0},
          Ray{Point3(0, 0, 0), Vector3(1, 0, 0), nan, 1.0}}) {
        HitRecord record;
        EXPECT_FALSE(bvh.intersect(ray, record, scratch)) << describe(ray);
        EXPECT_FALSE(bvh.occluded(ray, scratch)) << describe(ray);
        std::vector<HitRecord> hits;
        bvh.all_hits(ray, hits, scratch);
        EXPECT_TRUE(hits.empty()) << describe(ray);
    }
    // Rays the float box test cannot represent (far origins, huge or tiny directions) are
    // answered by visiting everything: slow, but still exactly brute force's answer.
    std::vector<Ray> extreme;
    test::Random random(10);
    for (int i = 0; i < 500; ++i) {
        const Vector3 towards =
            random.in_box(Aabb(Point3(-0.5, -0.5, -0.5), Point3(0.5, 0.5, 0.5)));
        const Vector3 direction = random.unit_vector();
        extreme.push_back(
            Ray{towards - 1e35 * direction, 1e-36 * direction.normalized(), 0.0, kInfinity});
        extreme.push_back(Ray{towards - 3.0 * direction, 1e40 * direction, 0.0, kInfinity});
        extreme.push_back(Ray{towards - 3.0 * direction, 1e-40 * direction, 0.0, kInfinity});
        extreme.push_back(Ray{towards, Vector3(direction.x(), 1e-45, 0.0), -kInfinity, kInfinity});
    }
    expect_same_answers<TriangleSet<double>>(bvh, brute, extreme, "extreme");
}

/// The primitives of the leaf (first, count), as Bvh::binary_nodes documents them. For a
/// triangle-block leaf it also checks that every used lane holds its triangle's corners bit
/// for bit and every unused lane is marked unused.
template <class Set>
std::vector<std::uint32_t> leaf_primitives(const Bvh<Set>& bvh, const Set& set, std::uint32_t first,
                                           std::uint32_t count) {
    std::vector<std::uint32_t> primitives;
    const BvhLeafTriangles& triangles = bvh.leaf_triangles();
    if (!triangles.empty()) {
        // Lanes 4 first .. 4 first + 4 ceil(count / 4) - 1: groups of eight while more than
        // four are left, then one of four; each lane's nine corners and index (BvhLeafTriangles).
        const std::uint32_t lanes = (count + 3) / 4 * 4;
        EXPECT_LE(10 * (std::size_t{4} * first + lanes), triangles.lanes.size());
        if (10 * (std::size_t{4} * first + lanes) > triangles.lanes.size()) return primitives;
        for (std::uint32_t k = 0; k < lanes; ++k) {
            const auto at = BvhLeafTriangles::place(first, count, k);
            EXPECT_EQ(at.width, k / 8 * 8 + 4 < count ? 8u : 4u);
            const std::uint32_t primitive = triangles.primitive(at);
            if (k >= count) {
                EXPECT_EQ(primitive, kNoIndex);
                continue;
            }
            EXPECT_LT(primitive, set.size());
            if (primitive >= set.size()) continue;
            primitives.push_back(primitive);
            if constexpr (std::is_same_v<Set, TriangleSet<float>>) {
                for (int corner = 0; corner < 3; ++corner) {
                    for (int axis = 0; axis < 3; ++axis) {
                        EXPECT_EQ(
                            std::bit_cast<std::uint32_t>(triangles.corner(at, corner, axis)),
                            std::bit_cast<std::uint32_t>(set.corner(primitive, corner)[axis]));
                    }
                }
            }
        }
    } else if (count == 1) {
        primitives.push_back(first);  // a one-primitive leaf names its primitive directly
    } else {
        const auto& indices = bvh.primitive_indices();
        EXPECT_LE(first + count, indices.size());
        for (std::uint32_t k = first; k < first + count && k < indices.size(); ++k)
            primitives.push_back(indices[k]);
    }
    return primitives;
}

/// Checks the tree's invariants: each primitive reached through exactly one leaf, each node's
/// box containing its children's boxes and its primitives' boxes.
template <class Set>
void expect_valid_tree(const Bvh<Set>& bvh, const Set& set, int width) {
    std::vector<int> reached(set.size(), 0);
    auto contains = [](const float* lower, const float* upper, const Aabb& box) {
        for (int axis = 0; axis < 3; ++axis) {
            if (!(lower[axis] <= box.lower[axis] && box.upper[axis] <= upper[axis])) return false;
        }
        return true;
    };
    auto check_leaf = [&](const float* lower, const float* upper, std::uint32_t first,
                          std::uint32_t count) {
        const std::vector<std::uint32_t> primitives = leaf_primitives(bvh, set, first, count);
        EXPECT_EQ(primitives.size(), count);
        for (std::uint32_t primitive : primitives) {
            EXPECT_TRUE(contains(lower, upper, set.bounds(primitive))) << primitive;
            ++reached[primitive];
        }
    };
    if (width == 2) {
        const auto& nodes = bvh.binary_nodes();
        ASSERT_FALSE(nodes.empty());
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            if (i == 1) continue;
            const BvhNode& node = nodes[i];
            if (node.is_leaf()) {
                check_leaf(node.lower, node.upper, node.offset, node.count);
                continue;
            }
            ASSERT_EQ(node.offset % 2, 0u);  // sibling pairs share a cache line
            for (std::uint32_t child = node.offset; child < node.offset + 2; ++child) {
                const BvhNode& c = nodes[child];
                EXPECT_TRUE(contains(node.lower, node.upper,
                                     Aabb(Point3(c.lower[0], c.lower[1], c.lower[2]),
                                          Point3(c.upper[0], c.upper[1], c.upper[2]))))
                    << i << " " << child;
            }
        }
    } else {
        auto check_wide = [&](const auto& nodes) {
            constexpr int kChildren = std::decay_t<decltype(nodes[0])>::kChildren;
            constexpr std::uint32_t kInterior = Bvh4Node::kInterior;
            ASSERT_FALSE(nodes.empty());
            for (std::size_t i = 0; i < nodes.size(); ++i) {
                const auto& node = nodes[i];
                for (int slot = 0; slot < kChildren; ++slot) {
                    const float lower[3] = {node.bounds[0][slot], node.bounds[2][slot],
                                            node.bounds[4][slot]};
                    const float upper[3] = {node.bounds[1][slot], node.bounds[3][slot],
                                            node.bounds[5][slot]};
                    if (node.count[slot] == 0) {
                        EXPECT_GT(lower[0], upper[0]) << "an unused slot has an empty box";
                        continue;
                    }
                    if (node.count[slot] != kInterior) {
                        check_leaf(lower, upper, node.first[slot], node.count[slot]);
                        continue;
                    }
                    ASSERT_GT(node.first[slot], i);  // children follow their parent
                    const auto& child = nodes[node.first[slot]];
                    for (int s = 0; s < kChildren; ++s) {
                        if (child.bounds[0][s] > child.bounds[1][s]) continue;  // unused slot
                        EXPECT_TRUE(contains(
                            lower, upper,
                            Aabb(Point3(child.bounds[0][s], child.bounds[2][s], child.bounds[4][s]),
                                 Point3(child.bounds[1][s], child.bounds[3][s],
                                        child.bounds[5][s]))))
                            << i << " slot " << slot;
                    }
                }
            }
        };
        if (width == 4) check_wide(bvh.nodes_4_wide());
        if (width == 8) check_wide(bvh.nodes_8_wide());
    }
    EXPECT_TRUE(std::all_of(reached.begin(), reached.end(), [](int r) { return r == 1; }))
        << "a primitive is missing from the leaves, or in two";
}

TEST(Bvh, TreeInvariantsAndStats) {
    const TestMesh mesh = test::sphere_mesh(6);
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    for (bool blocks : {true, false}) {
        for (int width : {2, 4, 8}) {
            const BvhConfig config{.width = width, .triangle_blocks = blocks};
            Bvh<TriangleSet<float>> bvh;
            bvh.build(set, config);
            expect_valid_tree(bvh, set, width);
            EXPECT_EQ(bvh.leaf_triangles().empty(), !blocks);
            EXPECT_EQ(bvh.primitive_indices().empty(), blocks);
            const AcceleratorStats stats = bvh.stats();
            EXPECT_EQ(stats.name, "bvh");
            EXPECT_EQ(stats.primitives, set.size());
            EXPECT_EQ(stats.references, set.size());
            // A node holds at most `width` leaves of at most max_leaf_size primitives.
            EXPECT_GE(stats.nodes, set.size() / std::size_t(width * config.max_leaf_size));
            EXPECT_GE(stats.build_milliseconds, 0.0);
            EXPECT_FALSE(stats.details.empty());
            // The memory target: nodes, indices and triangle blocks within 80 bytes a
            // triangle (the set's own triangles, 36 bytes each in float, not counted).
            EXPECT_LE(double(stats.bytes) / double(set.size()), 80.0) << stats.details;
        }
    }
    // Other sets and configurations keep the invariants too.
    const TestMesh stadium = teapot_in_stadium();
    const TriangleSet<double> stadium_set(stadium.vertices, stadium.triangles);
    const TriangleSet<float> stadium_floats(stadium.vertices, stadium.triangles);
    for (int bins : {2, 7, 32}) {
        const BvhConfig config{.bins = bins, .max_leaf_size = 1, .width = 8};
        Bvh<TriangleSet<double>> bvh;
        bvh.build(stadium_set, config);
        expect_valid_tree(bvh, stadium_set, 8);
        Bvh<TriangleSet<float>> blocks;
        blocks.build(stadium_floats, config);
        expect_valid_tree(blocks, stadium_floats, 8);
    }
}

TEST(Bvh, ParallelAndSerialBuildsMakeTheSameTree) {
    const TestMesh mesh = thin_triangle_soup(100000, 12);
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    Bvh<TriangleSet<float>> serial, parallel;
    serial.build(set, BvhConfig{.width = 2, .parallel = false});
    parallel.build(set, BvhConfig{.width = 2, .parallel = true});
    EXPECT_EQ(serial.stats().nodes, parallel.stats().nodes);
    EXPECT_EQ(serial.stats().details, parallel.stats().details);
    // The same topology gives the same work, ray by ray.
    QueryScratch scratch;
    for (const Ray& ray : mixed_rays(Aabb(Point3(0, 0, 0), Point3(1, 1, 1)), 500, 13)) {
        TraversalCounters a, b;
        HitRecord ra, rb;
        EXPECT_EQ(serial.intersect_counted(ray, ra, scratch, a),
                  parallel.intersect_counted(ray, rb, scratch, b));
        EXPECT_EQ(a.nodes_visited, b.nodes_visited);
        EXPECT_EQ(a.primitives_tested, b.primitives_tested);
    }
}

TEST(Bvh, PathologicalSpacingStaysWithinTheDepthBound) {
    // Triangles at x = 3^k, binned into 2 bins: only the largest lies in the upper bin, so
    // every binned split peels off one triangle and, without the depth limit, the tree would
    // be 158 levels deep, beyond what the traversal stack holds.
    TestMesh mesh;
    for (int k = -79; k <= 79; ++k) {
        const double x = std::pow(3.0, k);
        const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.insert(mesh.vertices.end(), {{x, 0, 0}, {x, 1, 0}, {x, 0, 1}});
        mesh.triangles.push_back({base, base + 1, base + 2});
    }
    const TriangleSet<double> set(mesh.vertices, mesh.triangles);
    BruteForce<TriangleSet<double>> brute;
    brute.build(set);
    for (int width : {2, 4, 8}) {
        Bvh<TriangleSet<double>> bvh;
        bvh.build(set, BvhConfig{.bins = 2, .max_leaf_size = 1, .width = width});
        const std::string details = bvh.stats().details;
        const int depth = std::stoi(details.substr(details.find("depth ") + 6));
        EXPECT_LE(depth, detail::kMaxDepth) << details;
        EXPECT_GT(depth, detail::kMaxSahDepth) << details;  // the limit was reached
        std::vector<Ray> rays;
        test::Random random(14);
        for (int i = 0; i < 2000; ++i) {
            const Point3 p(std::pow(3.0, random.uniform(-80, 80)), random.uniform(0, 0.5),
                           random.uniform(0, 0.5));
            rays.push_back(Ray{p + Vector3(0, 0, 5), Vector3(random.uniform(-1, 1), 0, -1)});
            rays.push_back(Ray{Point3(-1, p.y(), p.z()), Vector3(1, 0, 0)});
        }
        expect_same_answers<TriangleSet<double>>(bvh, brute, rays, "spacing");
    }
}

TEST(Bvh, CountedQueriesDoFarLessWorkThanBruteForce) {
    // sphere_mesh(6): 32768 triangles. Brute force tests all of them per ray; the 8-wide BVH
    // visits about 8 nodes (leaves included) and tests about 2.6 triangles per ray here
    // (measured), so nodes + triangles per ray must stay under 1/1000 of brute force's
    // triangle tests (about 10 against 33: a factor 3 of headroom).
    const test::BuiltMesh<float, Bvh> built(test::sphere_mesh(6));
    const auto& [set, brute, bvh] = built;
    QueryScratch scratch;
    test::Random random(15);
    TraversalCounters tree, naive;
    const int rays = 2000;
    for (int i = 0; i < rays; ++i) {
        const Ray ray = random.ray_between(Aabb(Point3(-4, -4, -4), Point3(4, 4, 4)),
                                           Aabb(Point3(-1, -1, -1), Point3(1, 1, 1)));
        HitRecord a, b;
        ASSERT_EQ(bvh.intersect_counted(ray, a, scratch, tree),
                  brute.intersect_counted(ray, b, scratch, naive));
    }
    EXPECT_EQ(naive.primitives_tested, std::uint64_t(rays) * set.size());
    EXPECT_GE(tree.nodes_visited, std::uint64_t(rays));  // at least the root, every ray
    EXPECT_EQ(tree.boxes_tested % 4, 0u);                // four boxes per 4-wide node
    EXPECT_LT((tree.nodes_visited + tree.primitives_tested) * 1000, naive.primitives_tested);
}

TEST(Bvh, ConcurrentQueriesGiveTheSameAnswers) {
    const TestMesh mesh = test::sphere_mesh(5);
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    Bvh<TriangleSet<float>> bvh;
    bvh.build(set);
    const std::vector<Ray> rays = mixed_rays(test::mesh_bounds(mesh), 20000, 16);
    std::vector<Answer> expected(rays.size());
    QueryScratch scratch;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        HitRecord record;
        expected[i] = Answer::of(bvh.intersect(rays[i], record, scratch), record);
    }
    std::vector<int> mismatches(4, 0);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&, t] {
            QueryScratch own;
            for (std::size_t i = t; i < rays.size(); i += 2) {
                HitRecord record;
                const Answer answer = Answer::of(bvh.intersect(rays[i], record, own), record);
                mismatches[t] += !(answer == expected[i]);
                mismatches[t] += bvh.occluded(rays[i], own) != expected[i].hit;
            }
        });
    }
    for (auto& thread : threads) thread.join();
    EXPECT_EQ(mismatches, std::vector<int>(4, 0));
}

TEST(Bvh, BadConfigsThrowAndTheFactoryBuildsIt) {
    const TestMesh mesh = test::integer_cube(2);
    const TriangleSet<float> set(mesh.vertices, mesh.triangles);
    Bvh<TriangleSet<float>> bvh;
    EXPECT_THROW(bvh.build(set, BvhConfig{.bins = 1}), InvalidParameter);
    EXPECT_THROW(bvh.build(set, BvhConfig{.bins = 257}), InvalidParameter);
    EXPECT_THROW(bvh.build(set, BvhConfig{.max_leaf_size = 0}), InvalidParameter);
    EXPECT_THROW(bvh.build(set, BvhConfig{.traversal_cost = 0.0}), InvalidParameter);
    EXPECT_THROW(bvh.build(set, BvhConfig{.intersection_cost = -1.0}), InvalidParameter);
    EXPECT_THROW(bvh.build(set, BvhConfig{.width = 3}), InvalidParameter);

    const auto names = accelerator_names();
    EXPECT_NE(std::find(names.begin(), names.end(), "bvh"), names.end());
    const auto structure = make_accelerator("bvh", set);
    EXPECT_EQ(structure->name(), "bvh");
    QueryScratch scratch;
    HitRecord record;
    ASSERT_TRUE(structure->intersect(Ray{Point3(1, 1, 5), Vector3(0, 0, -1)}, record, scratch));
    EXPECT_EQ(record.t, 3.0);
}

}  // namespace
}  // namespace csgrt
