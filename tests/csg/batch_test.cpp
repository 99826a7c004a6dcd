#include "csgrt/csg/batch.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <limits>
#include <vector>

#include "csgrt/accel/closest_point.h"
#include "csgrt/accel/factory.h"
#include "csgrt/core/box.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/plane.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/painted.h"
#include "csgrt/mesh/mesh.h"
#include "support/meshes.h"
#include "support/precisions.h"
#include "support/random.h"
#include "support/rays.h"

namespace csgrt {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A scene of every kind of object the batch must pass through: an analytic sphere, a CSG
// difference, an instanced box, a closed mesh, and the unbounded ground.
Scene mixed_scene() {
    Scene scene;
    // Materials 1 and 2 for two objects, 3 painted on the subtracted ball (the bite's surface).
    for (const char* name : {"a", "b", "c"}) {
        scene.add_material(Material{name, Vector3(0.5, 0.5, 0.5)});
    }
    scene.add_object(std::make_shared<Sphere>(Point3(-2, 1, 0), 1.0), 1);
    scene.add_object(make_difference(std::make_shared<Box>(Point3(1, 0, -1), Point3(3, 2, 1)),
                                     {std::make_shared<Painted>(
                                         std::make_shared<Sphere>(Point3(2, 2, 0), 0.8), 3)}),
                     2);
    Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Vector3(0, 1, 0)).toRotationMatrix();
    scene.add_object(std::make_shared<Instance>(
        std::make_shared<Box>(Point3(-0.5, 0, -0.5), Point3(0.5, 1, 0.5)),
        Transform(rotation, Vector3(0, 0, 3))));
    const test::TestMesh sphere = test::sphere_mesh(3);
    TriangleMeshData data{sphere.vertices, sphere.triangles, {}};
    for (auto& v : data.vertices) v = v * 0.7 + Vector3(0, 1, -3);
    scene.add_object(std::make_shared<Mesh>(std::move(data)));
    scene.add_object(std::make_shared<Plane>(Point3(0, 0, 0), Normal3(0, 1, 0)));
    scene.commit();
    return scene;
}

// Rays as an (N, 6) array of Real and an interval per ray; the last few are invalid.
template <class Real>
struct RayBuffer {
    std::vector<Real> rays;  // ox oy oz dx dy dz per ray
    std::vector<Real> t_min, t_max;
    std::size_t size() const { return t_min.size(); }
    RayArrays<Real> arrays() const {
        RayArrays<Real> view;
        view.origins = strided_vectors(rays.data(), size(), 6);
        view.directions = strided_vectors(rays.data() + 3, size(), 6);
        view.t_min = t_min;
        view.t_max = t_max;
        return view;
    }
    void add(const Ray& ray) {
        for (int k = 0; k < 3; ++k) rays.push_back(static_cast<Real>(ray.origin[k]));
        for (int k = 0; k < 3; ++k) rays.push_back(static_cast<Real>(ray.direction[k]));
        t_min.push_back(static_cast<Real>(ray.t_min));
        t_max.push_back(static_cast<Real>(ray.t_max));
    }
};

template <class Real>
RayBuffer<Real> scene_rays(int count) {
    RayBuffer<Real> buffer;
    const Aabb box(Point3(-4, -0.5, -4), Point3(4, 3, 4));
    for (const Ray& ray : test::camera_rays(box, count / 2, 11)) buffer.add(ray);
    std::vector<Ray> inside = test::incoherent_rays(box, count - count / 2, 12);
    test::Random random(13);
    for (Ray& ray : inside) {
        test::random_interval(random, ray);
        buffer.add(ray);
    }
    // Invalid rays: NaN origin, zero direction, empty interval, infinite direction.
    buffer.add(Ray{Point3(kNaN, 0, 0), Vector3(0, 0, 1)});
    buffer.add(Ray{Point3(0, 1, 8), Vector3(0, 0, 0)});
    buffer.add(Ray{Point3(0, 1, 8), Vector3(0, 0, -1), 5.0, 4.0});
    buffer.add(Ray{Point3(0, 1, 8), Vector3(0, 0, -kInfinity)});
    return buffer;
}

// Every output of the nearest-hit batch, as owned vectors.
template <class Real>
struct NearestHits {
    std::vector<Real> t, uv, geometric, shading;
    std::vector<std::uint32_t> object, primitive, material;
    /// Filled with values no query writes (-7, id 7 is not the miss's kNoIndex either), so a
    /// slot the batch left unwritten shows.
    explicit NearestHits(std::size_t n)
        : t(n, Real(-7)),
          uv(2 * n, Real(-7)),
          geometric(3 * n, Real(-7)),
          shading(3 * n, Real(-7)),
          object(n, 7u),
          primitive(n, 7u),
          material(n, 7u) {}
    NearestHitOutputs<Real> outputs() { return {t, object, primitive, uv, geometric, shading, {}}; }
    /// With the material, which only a scene has.
    NearestHitOutputs<Real> scene_outputs() {
        return {t, object, primitive, uv, geometric, shading, material};
    }
    bool operator==(const NearestHits&) const = default;
};

template <class Real>
NearestHitOutputs<Real> only_t(std::vector<Real>& t) {
    NearestHitOutputs<Real> outputs;
    outputs.t = t;
    return outputs;
}

BatchConfig threads(int count) {
    BatchConfig config;
    config.threads = count;
    return config;
}

template <class Real>
class BatchTest : public ::testing::Test {};
TYPED_TEST_SUITE(BatchTest, test::Precisions);

TYPED_TEST(BatchTest, SceneNearestHitsAreTheSingleRayAnswersForEveryThreadCount) {
    using Real = TypeParam;
    const Scene scene = mixed_scene();
    const RayBuffer<Real> buffer = scene_rays<Real>(3000);
    const std::size_t n = buffer.size();
    NearestHits<Real> one(n);
    intersect(scene, buffer.arrays(), one.scene_outputs(), BatchConfig{1, 64});

    QueryScratch scratch;
    std::size_t hits = 0, painted_hits = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const auto hit = scene.intersect(buffer.arrays().ray(i), scratch);
        if (!hit) {
            ASSERT_EQ(one.t[i], std::numeric_limits<Real>::infinity()) << i;
            ASSERT_EQ(one.object[i], kNoIndex);
            ASSERT_EQ(one.primitive[i], kNoIndex);
            ASSERT_EQ(one.material[i], kNoIndex);
            ASSERT_EQ(one.geometric[3 * i], Real(0));
            continue;
        }
        ++hits;
        // The surface's material: the painted ball's inside the bite, else the object's.
        const std::uint32_t material =
            hit->material != kNoIndex ? hit->material : scene.objects()[hit->object_id].material;
        ASSERT_EQ(one.material[i], material) << i;
        painted_hits += hit->material == 3u ? 1 : 0;
        ASSERT_EQ(one.t[i], static_cast<Real>(hit->t)) << i;
        ASSERT_EQ(one.object[i], hit->object_id) << i;
        ASSERT_EQ(one.primitive[i], hit->primitive_id) << i;
        ASSERT_EQ(one.uv[2 * i], static_cast<Real>(hit->uv.x())) << i;
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(one.geometric[3 * i + k], static_cast<Real>(hit->geometric_normal[k]));
            ASSERT_EQ(one.shading[3 * i + k], static_cast<Real>(hit->shading_normal[k]));
        }
    }
    EXPECT_GT(hits, n / 3);       // the rays do reach the objects
    EXPECT_GT(painted_hits, 0u);  // and the bite
    for (std::size_t k = n - 4; k < n; ++k) EXPECT_EQ(one.object[k], kNoIndex);  // invalid

    for (int threads : {2, 3, 0}) {
        NearestHits<Real> many(n);
        intersect(scene, buffer.arrays(), many.scene_outputs(), BatchConfig{threads, 7});
        EXPECT_TRUE(many == one) << threads << " threads";
    }
}

TYPED_TEST(BatchTest, SceneOcclusionCrossingsAndMembership) {
    using Real = TypeParam;
    const Scene scene = mixed_scene();
    const RayBuffer<Real> buffer = scene_rays<Real>(1000);
    const std::size_t n = buffer.size();
    std::vector<std::uint8_t> occluded_out(n);
    occluded(scene, buffer.arrays(), std::span<std::uint8_t>(occluded_out), BatchConfig{2, 16});
    QueryScratch scratch;
    for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(occluded_out[i] != 0, scene.occluded(buffer.arrays().ray(i), scratch)) << i;
    }

    // Crossings against the closed form: a ray through the sphere's centre (-2, 1, 0), radius
    // 1, enters at t = 4 and leaves at t = 6 before reaching the ground at y = 0 behind it.
    RayBuffer<Real> through;
    through.add(Ray{Point3(-2, 1, 5), Vector3(0, 0, -1)});
    through.add(Ray{Point3(-2, 1, 5), Vector3(0, 0, -1), 0.0, 5.0});  // stops inside
    std::vector<std::uint32_t> counts(2);
    count_crossings(scene, through.arrays(), std::span<std::uint32_t>(counts));
    EXPECT_EQ(counts[0], 2u);
    EXPECT_EQ(counts[1], 1u);
    std::vector<std::uint64_t> offsets(3);
    crossing_offsets(counts, offsets);
    std::vector<Real> t(offsets[2]);
    std::vector<std::uint32_t> object(offsets[2]), primitive(offsets[2]);
    std::vector<std::uint8_t> entering(offsets[2]);
    list_crossings(scene, through.arrays(),
                   CrossingOutputs<Real>{offsets, t, object, primitive, {}, entering});
    EXPECT_EQ(t, (std::vector<Real>{4, 6, 4}));
    EXPECT_EQ(object, (std::vector<std::uint32_t>{0, 0, 0}));
    EXPECT_EQ(entering, (std::vector<std::uint8_t>{1, 0, 1}));
    // Offsets that do not come from the same rays are refused, not overrun.
    std::vector<std::uint64_t> wrong{0, 1, 3};
    EXPECT_THROW(list_crossings(scene, through.arrays(),
                                CrossingOutputs<Real>{wrong, t, object, primitive, {}, entering}),
                 InvalidParameter);

    // Membership against the solids' definitions: inside the sphere, or the box minus the
    // ball; points on the instanced box and the mesh are compared with their own contains.
    test::Random random(3);
    std::vector<Real> points;
    std::vector<Point3> exact;
    for (int i = 0; i < 2000; ++i) {
        const Point3 p = random.in_box(Aabb(Point3(-4, -0.5, -4), Point3(4, 3, 4)));
        for (int k = 0; k < 3; ++k) points.push_back(static_cast<Real>(p[k]));
        exact.emplace_back(double(points[points.size() - 3]), double(points[points.size() - 2]),
                           double(points.back()));
    }
    points.push_back(Real(kNaN)), points.push_back(0), points.push_back(0);
    std::vector<std::uint8_t> inside(exact.size() + 1);
    contains(scene, interleaved_vectors<Real>(points, "points"), std::span<std::uint8_t>(inside),
             BatchConfig{0, 100});
    std::size_t in_count = 0;
    for (std::size_t i = 0; i < exact.size(); ++i) {
        const Point3& p = exact[i];
        const bool in_ball = (p - Point3(-2, 1, 0)).norm() < 1.0;
        const bool in_bitten = Aabb(Point3(1, 0, -1), Point3(3, 2, 1)).contains(p) &&
                               (p - Point3(2, 2, 0)).norm() > 0.8;
        const bool in_others =
            scene.objects()[2].shape->contains(p) || scene.objects()[3].shape->contains(p);
        ASSERT_EQ(inside[i] != 0, in_ball || in_bitten || in_others) << p.transpose();
        in_count += inside[i];
    }
    EXPECT_GT(in_count, 50u);
    EXPECT_EQ(inside.back(), 0);  // a NaN point is outside
}

// One mesh (a subdivided sphere) in a triangle set with the BVH over it, and a second mesh (a
// cube) appended, so the ids are (mesh, triangle within the mesh).
template <class Real>
struct TwoMeshes {
    TriangleSet<Real> set;
    std::unique_ptr<Accelerator<TriangleSet<Real>>> bvh, brute;
    std::unique_ptr<ClosestPointTree<Real>> tree;
    std::vector<std::uint32_t> object_of, first{0, 0};
    test::TestMesh joined;
    std::size_t sphere_triangles = 0;

    TwoMeshes() {
        joined = test::sphere_mesh(3);
        sphere_triangles = joined.triangles.size();
        const test::TestMesh cube = test::integer_cube(2);
        const auto offset = static_cast<std::uint32_t>(joined.vertices.size());
        for (const auto& v : cube.vertices) joined.vertices.push_back(v + Vector3(3, -1, -1));
        for (auto t : cube.triangles) {
            joined.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
        }
        set = TriangleSet<Real>(joined.vertices, joined.triangles);
        bvh = make_accelerator("bvh", set);
        brute = make_accelerator("brute", set);
        tree = std::make_unique<ClosestPointTree<Real>>(set);
        object_of.assign(joined.triangles.size(), 0);
        for (std::size_t i = sphere_triangles; i < object_of.size(); ++i) object_of[i] = 1;
        first[1] = static_cast<std::uint32_t>(sphere_triangles);
    }
    TriangleStructure<Real> structure(bool use_brute = false) const {
        return {&set, use_brute ? brute.get() : bvh.get(), tree.get(), object_of, first};
    }
};

TYPED_TEST(BatchTest, TriangleQueriesAgainstTheStructureBruteForceAndMembership) {
    using Real = TypeParam;
    const TwoMeshes<Real> meshes;
    RayBuffer<Real> buffer;
    const Aabb box(Point3(-1.2, -1.2, -1.2), Point3(5.2, 1.2, 1.2));
    for (const Ray& ray : test::incoherent_rays(box, 2000, 21)) buffer.add(ray);
    buffer.add(Ray{Point3(0, 0, 0), Vector3(0, 0, 0)});
    const std::size_t n = buffer.size();

    NearestHits<Real> all(n);
    intersect(meshes.structure(), buffer.arrays(), all.outputs(), BatchConfig{2, 32});
    // Only t: the same t, and nothing else written.
    std::vector<Real> t_only(n);
    intersect(meshes.structure(), buffer.arrays(), only_t(t_only), threads(1));
    EXPECT_EQ(t_only, all.t);
    // Triangles have no materials: asking for them is an error, not a column of kNoIndex.
    EXPECT_THROW(intersect(meshes.structure(), buffer.arrays(), all.scene_outputs(), threads(1)),
                 InvalidParameter);

    QueryScratch scratch;
    std::vector<HitRecord> brute_hits;
    std::vector<std::uint32_t> counts(n);
    count_crossings(meshes.structure(), buffer.arrays(), std::span<std::uint32_t>(counts),
                    BatchConfig{3, 50});
    for (std::size_t i = 0; i < n; ++i) {
        const Ray ray = buffer.arrays().ray(i);
        HitRecord record;
        if (!meshes.bvh->intersect(ray, record, scratch)) {
            // A miss as the header defines it: every output written, t infinite, ids kNoIndex,
            // uv and normals zero.
            ASSERT_EQ(all.t[i], std::numeric_limits<Real>::infinity());
            ASSERT_EQ(all.primitive[i], kNoIndex);
            ASSERT_EQ(all.object[i], kNoIndex);
            ASSERT_EQ(all.uv[2 * i], Real(0));
            ASSERT_EQ(all.uv[2 * i + 1], Real(0));
            for (int k = 0; k < 3; ++k) {
                ASSERT_EQ(all.geometric[3 * i + k], Real(0));
                ASSERT_EQ(all.shading[3 * i + k], Real(0));
            }
            ASSERT_EQ(counts[i], 0u);
            continue;
        }
        ASSERT_EQ(all.t[i], static_cast<Real>(record.t));
        const bool on_cube = record.primitive >= meshes.sphere_triangles;
        ASSERT_EQ(all.object[i], on_cube ? 1u : 0u);
        ASSERT_EQ(all.primitive[i],
                  record.primitive - (on_cube ? std::uint32_t(meshes.sphere_triangles) : 0u));
        ASSERT_EQ(all.uv[2 * i + 1], static_cast<Real>(record.v));
        const Normal3 n_expected = triangle_normal(meshes.set, record.primitive);
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(all.geometric[3 * i + k], static_cast<Real>(n_expected[k]));
            ASSERT_EQ(all.shading[3 * i + k], static_cast<Real>(n_expected[k]));
        }
        ASSERT_EQ(all.uv[2 * i], static_cast<Real>(record.u));
        // Crossings against brute force's list of every hit (these random rays pass through no
        // shared edge, so every hit is a crossing).
        brute_hits.clear();
        meshes.brute->all_hits(ray, brute_hits, scratch);
        ASSERT_EQ(counts[i], brute_hits.size()) << i;
    }

    // Membership: the parity rule against the sphere mesh's Mesh::contains and the cube's
    // definition, on points away from the surfaces.
    const test::TestMesh sphere_only = test::sphere_mesh(3);
    const Mesh sphere(TriangleMeshData{sphere_only.vertices, sphere_only.triangles, {}});
    test::Random random(8);
    std::vector<Real> points;
    for (int i = 0; i < 1500; ++i) {
        const Point3 p = random.in_box(test::enlarged(box, 0.1));
        for (int k = 0; k < 3; ++k) points.push_back(static_cast<Real>(p[k]));
    }
    const VectorArray<Real> view = interleaved_vectors<Real>(points, "points");
    std::vector<std::uint8_t> inside(view.count);
    contains(meshes.structure(), view, std::span<std::uint8_t>(inside), BatchConfig{2, 64});
    std::vector<Real> distance(view.count), signed_distance(view.count), closest(3 * view.count);
    std::vector<std::uint32_t> object(view.count);
    ClosestPointOutputs<Real> outputs;
    outputs.point = closest;
    outputs.object_id = object;
    outputs.distance = distance;
    outputs.signed_distance = signed_distance;
    closest_points(meshes.structure(), view, outputs, BatchConfig{2, 64});
    std::size_t in_count = 0;
    for (std::size_t i = 0; i < view.count; ++i) {
        const Point3 p = view[i];
        const bool expected =
            sphere.contains(p) || Aabb(Point3(3, -1, -1), Point3(5, 1, 1)).contains(p);
        // Within 1e-6 of a surface the parity and the reference may disagree on a rounding.
        if (distance[i] > Real(1e-4)) {
            ASSERT_EQ(inside[i] != 0, expected) << p.transpose();
        }
        in_count += inside[i];
        const ClosestPoint reference = meshes.tree->closest(p);
        ASSERT_EQ(distance[i], static_cast<Real>(std::sqrt(reference.squared_distance)));
        ASSERT_EQ(signed_distance[i], inside[i] ? -distance[i] : distance[i]);
        ASSERT_EQ(closest[3 * i], static_cast<Real>(reference.point.x()));
        ASSERT_EQ(object[i], reference.primitive >= meshes.sphere_triangles ? 1u : 0u);
    }
    EXPECT_GT(in_count, 100u);
}

TYPED_TEST(BatchTest, CameraRaysThroughTheBvhPacketsAnswerAsSingleRays) {
    // Rays from one eye go through Bvh's packet queries eight at a time (as one interval ray,
    // with ray-parallel triangle tests): the answers must be the single-ray queries', ray by
    // ray, for blocks that split packets (grain 13) and for brute force's answers too.
    using Real = TypeParam;
    const TwoMeshes<Real> meshes;
    RayBuffer<Real> buffer;
    const Point3 eye(1.9, 0.7, 6.0);
    const int width = 61;
    for (int y = 0; y < width; ++y) {
        for (int x = 0; x < width; ++x) {
            const Point3 target(-1.2 + 6.4 * (x + 0.5) / width, -1.2 + 2.4 * (y + 0.5) / width,
                                0.0);
            buffer.add(Ray{eye, target - eye});
        }
    }
    const std::size_t n = buffer.size();
    NearestHits<Real> all(n);
    intersect(meshes.structure(), buffer.arrays(), all.outputs(), BatchConfig{2, 13});
    std::vector<std::uint8_t> occluded_out(n);
    occluded(meshes.structure(), buffer.arrays(), std::span<std::uint8_t>(occluded_out),
             BatchConfig{2, 13});
    QueryScratch scratch;
    std::size_t hits = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const Ray ray = buffer.arrays().ray(i);
        HitRecord single, brute;
        const bool hit = meshes.bvh->intersect(ray, single, scratch);
        ASSERT_EQ(hit, meshes.brute->intersect(ray, brute, scratch)) << i;
        ASSERT_EQ(occluded_out[i] != 0, hit) << i;
        if (!hit) {
            ASSERT_EQ(all.t[i], std::numeric_limits<Real>::infinity()) << i;
            continue;
        }
        ++hits;
        ASSERT_EQ(single.t, brute.t) << i;
        ASSERT_EQ(all.t[i], static_cast<Real>(single.t)) << i;
        ASSERT_EQ(all.uv[2 * i], static_cast<Real>(single.u)) << i;
        ASSERT_EQ(all.uv[2 * i + 1], static_cast<Real>(single.v)) << i;
    }
    // The grid covers both meshes and the gap between them.
    EXPECT_GT(hits, n / 4);
    EXPECT_LT(hits, n);
}

TYPED_TEST(BatchTest, SeparateArraysAndWrongSizesAreRefused) {
    using Real = TypeParam;
    const Scene scene = mixed_scene();
    // Struct-of-arrays rays give the answers of the interleaved ones.
    const RayBuffer<Real> buffer = scene_rays<Real>(200);
    const std::size_t n = buffer.size();
    std::array<std::vector<Real>, 6> columns;
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 6; ++k) columns[k].push_back(buffer.rays[6 * i + k]);
    }
    RayArrays<Real> soa;
    soa.origins = separate_vectors<Real>(columns[0], columns[1], columns[2], "origins");
    soa.directions = separate_vectors<Real>(columns[3], columns[4], columns[5], "directions");
    soa.t_min = buffer.t_min;
    soa.t_max = buffer.t_max;
    NearestHits<Real> a(n), b(n);
    intersect(scene, buffer.arrays(), a.outputs());
    intersect(scene, soa, b.outputs());
    EXPECT_TRUE(a == b);

    std::vector<Real> short_t(n - 1);
    EXPECT_THROW(intersect(scene, soa, only_t(short_t)), InvalidParameter);
    std::vector<Real> odd(7);
    EXPECT_THROW(interleaved_vectors<Real>(odd, "origins"), InvalidParameter);
    EXPECT_THROW(separate_vectors<Real>(columns[0], columns[1], short_t, "origins"),
                 InvalidParameter);
    std::vector<Real> t(n);
    EXPECT_THROW(intersect(scene, soa, only_t(t), threads(-1)), InvalidParameter);
    Scene uncommitted;
    EXPECT_THROW(intersect(uncommitted, soa, only_t(t)), InvalidParameter);
}

}  // namespace
}  // namespace csgrt
