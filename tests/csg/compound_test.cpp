#include "csgrt/csg/compound.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <filesystem>

#include "csgrt/core/box.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/plane.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/complement.h"
#include "csgrt/csg/scene.h"
#include "csgrt/csg/scene_file.h"
#include "csgrt/mesh/mesh.h"
#include "support/meshes.h"
#include "support/random.h"
#include "support/scene_parts.h"
#include "support/shape_properties.h"
#include "support/test_scale.h"

namespace csgrt {
namespace {

using Shapes = std::vector<std::shared_ptr<const Shape>>;

std::shared_ptr<const Shape> sphere(double x, double y, double z, double radius) {
    return std::make_shared<Sphere>(Point3(x, y, z), radius);
}

// Test fixture: forwards to a shape and counts the nearest_hit and any_hit calls it receives.
class Counted final : public Shape {
public:
    Counted(std::shared_ptr<const Shape> shape, std::atomic<long>& calls)
        : shape_(std::move(shape)), calls_(calls) {}
    std::string_view kind() const override { return shape_->kind(); }
    Aabb bounds() const override { return shape_->bounds(); }
    bool is_solid() const override { return shape_->is_solid(); }
    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override {
        calls_.fetch_add(1, std::memory_order_relaxed);
        return shape_->nearest_hit(ray, record, scratch);
    }
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override {
        calls_.fetch_add(1, std::memory_order_relaxed);
        return shape_->any_hit(ray, scratch);
    }
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override {
        shape_->find_spans(ray, spans, scratch);
    }
    bool contains(const Point3& p) const override { return shape_->contains(p); }

private:
    std::shared_ptr<const Shape> shape_;
    std::atomic<long>& calls_;
};

// Spheres on a jittered grid, never overlapping or touching: cells of 2 with radius <= 0.8 and
// jitter <= 0.15 leave a gap of at least 0.1 between neighbours.
Shapes disjoint_spheres(int per_side, std::uint64_t seed) {
    test::Random random(seed);
    Shapes spheres;
    for (int i = 0; i < per_side; ++i) {
        for (int j = 0; j < per_side; ++j) {
            for (int k = 0; k < per_side; ++k) {
                spheres.push_back(sphere(
                    2.0 * i + random.uniform(-0.15, 0.15), 2.0 * j + random.uniform(-0.15, 0.15),
                    2.0 * k + random.uniform(-0.15, 0.15), random.uniform(0.3, 0.8)));
            }
        }
    }
    return spheres;
}

// An independent description of a union of disjoint spheres: the signed distance to the nearest.
test::SurfaceDescription spheres_surface(const Shapes& spheres) {
    auto nearest = [spheres](const Point3& p) {
        const Sphere* best = nullptr;
        double best_distance = kInfinity;
        for (const auto& shape : spheres) {
            const auto& s = static_cast<const Sphere&>(*shape);
            const double distance = (p - s.center()).norm() - s.radius();
            if (distance < best_distance) best_distance = distance, best = &s;
        }
        return best;
    };
    test::SurfaceDescription surface;
    surface.value = [nearest](const Point3& p) {
        const Sphere* s = nearest(p);
        return (p - s->center()).norm() - s->radius();
    };
    surface.gradient = [nearest](const Point3& p) {
        return Vector3((p - nearest(p)->center()).normalized());
    };
    surface.scale = 1.0;
    for (const auto& s : spheres) surface.region.extend(s->bounds());
    return surface;
}

TEST(Compound, NearestChildWinsAndNamesItsIndex) {
    const Compound compound({sphere(0, 0, 10, 1), sphere(0, 0, 4, 1), sphere(0, 0, 7, 1)});
    const auto hit = compound.intersect(Ray{Point3(0, 0, 0), Vector3(0, 0, 2)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 1.5);  // z = 3 on the sphere around z = 4, direction length 2
    EXPECT_EQ(hit->object_id, 1u);
    EXPECT_EQ(hit->shape, &compound.child(1));
    EXPECT_TRUE(hit->geometric_normal.isApprox(Normal3(0, 0, -1)));
    EXPECT_TRUE(hit->front_face);
    EXPECT_TRUE(compound.occluded(Ray{Point3(0, 0, 0), Vector3(0, 0, 1)}));
    EXPECT_FALSE(compound.intersect(Ray{Point3(0, 5, 0), Vector3(0, 0, 1)}));
    EXPECT_FALSE(compound.occluded(Ray{Point3(0, 5, 0), Vector3(0, 0, 1)}));
}

TEST(Compound, EqualTGoesToTheLowerChildIndex) {
    // Two identical spheres: the same roots bit for bit, whichever structure asks.
    for (const char* name : {"brute", "auto"}) {
        Shapes children = disjoint_spheres(2, 5);
        children.push_back(sphere(20, 0, 0, 1));
        children.push_back(sphere(20, 0, 0, 1));
        const Compound compound(children, test::structure_named<CompoundConfig>(name));
        const auto hit = compound.intersect(Ray{Point3(20, 0, -5), Vector3(0, 0, 1)});
        ASSERT_TRUE(hit) << name;
        EXPECT_EQ(hit->object_id, 8u) << name;
        EXPECT_EQ(hit->shape, &compound.child(8)) << name;
    }
}

TEST(Compound, IntervalIsHonouredAtBothEnds) {
    const Compound compound({sphere(0, 0, 5, 1), sphere(0, 0, 10, 1)});
    Ray ray{Point3(0, 0, 0), Vector3(0, 0, 1), 4.0, 9.0};
    EXPECT_DOUBLE_EQ(compound.intersect(ray)->t, 4.0);
    ray.t_min = 4.0 + 1e-9;  // inside the first sphere: its exit at 6
    EXPECT_DOUBLE_EQ(compound.intersect(ray)->t, 6.0);
    ray.t_min = 6.5;  // past the first; the second enters at 9, exactly t_max
    EXPECT_DOUBLE_EQ(compound.intersect(ray)->t, 9.0);
    EXPECT_EQ(compound.intersect(ray)->object_id, 1u);
    ray.t_max = 9.0 - 1e-9;
    EXPECT_FALSE(compound.intersect(ray));
    EXPECT_FALSE(compound.occluded(ray));
}

TEST(Compound, UnboundedChildrenAreAskedOnEveryRayAndTieByIndex) {
    auto ground = test::ground_plane();
    const Compound compound({sphere(0, 1, 0, 1), ground, sphere(5, 3, 0, 1)});
    EXPECT_FALSE(compound.bounds().is_finite());
    // Straight down onto the sphere that rests on the ground: the sphere first.
    auto hit = compound.intersect(Ray{Point3(0, 10, 0), Vector3(0, -1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 8.0);
    EXPECT_EQ(hit->object_id, 0u);
    // Far from every sphere: the ground, child 1.
    hit = compound.intersect(Ray{Point3(100, 10, 100), Vector3(0, -1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 10.0);
    EXPECT_EQ(hit->object_id, 1u);
    EXPECT_EQ(hit->shape, ground.get());
    // Touching point of sphere 0 and the ground, hit from below at t = 10 by both: child 0.
    hit = compound.intersect(Ray{Point3(0, -10, 0), Vector3(0, 1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 10.0);
    EXPECT_EQ(hit->object_id, 0u);
    // The ground before sphere 2 when the ray comes from below, with the order reversed.
    const Compound reversed({sphere(5, 3, 0, 1), ground});
    hit = reversed.intersect(Ray{Point3(5, -1, 0), Vector3(0, 1, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->object_id, 1u);
    EXPECT_DOUBLE_EQ(hit->t, 1.0);
    EXPECT_TRUE(compound.occluded(Ray{Point3(100, 10, 100), Vector3(0, -1, 0)}));
    EXPECT_FALSE(compound.is_solid());
}

TEST(Compound, SolidOnlyWhenEveryChildIsASolid) {
    EXPECT_TRUE(Compound({sphere(0, 0, 0, 1), sphere(3, 0, 0, 1)}).is_solid());
    EXPECT_FALSE(Compound({sphere(0, 0, 0, 1), test::ground_plane()}).is_solid());
    EXPECT_FALSE(Compound(Shapes{}).is_solid());
    const Compound empty{Shapes{}};
    EXPECT_FALSE(empty.intersect(Ray{Point3(0, 0, 0), Vector3(1, 0, 0)}));
    EXPECT_TRUE(empty.bounds().is_empty());
    EXPECT_EQ(empty.accelerator_name(), "");
    // A non-solid compound is no CSG operand.
    EXPECT_THROW(
        Boolean(BooleanOperation::Union, sphere(0, 0, 0, 1),
                std::make_shared<Compound>(Shapes{sphere(0, 0, 0, 1), test::ground_plane()})),
        InvalidParameter);
}

TEST(Compound, BadArgumentsThrow) {
    EXPECT_THROW(Compound({sphere(0, 0, 0, 1), nullptr}), InvalidParameter);
    EXPECT_THROW(Compound({sphere(0, 0, 0, 1)}, test::structure_named<CompoundConfig>("octree")),
                 InvalidParameter);
    EXPECT_THROW(make_hierarchy({}), InvalidParameter);
    EXPECT_THROW(make_hierarchy({sphere(0, 0, 0, 1)}, 1), InvalidParameter);
    EXPECT_THROW(make_hierarchy({sphere(0, 0, 0, 1), nullptr}), InvalidParameter);
}

TEST(Compound, InvalidRaysHitNothing) {
    const Compound compound({sphere(0, 0, 0, 1), test::ground_plane()});
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const Ray& ray :
         {Ray{Point3(nan, 0, 0), Vector3(0, 0, 1)}, Ray{Point3(0, 0, -5), Vector3(0, kInfinity, 1)},
          Ray{Point3(0, 0, -5), Vector3(0, 0, 0)},
          Ray{Point3(0, 0, -5), Vector3(0, 0, 1), 3.0, 2.0}}) {
        EXPECT_FALSE(compound.intersect(ray));
        EXPECT_FALSE(compound.occluded(ray));
        EXPECT_TRUE(compound.spans(ray).empty());
    }
}

TEST(Compound, ChooseAcceleratorRule) {
    std::string reason;
    EXPECT_EQ(choose_accelerator(0, reason), "brute");
    EXPECT_EQ(choose_accelerator(kHandfulOfMembers, reason), "brute");
    EXPECT_NE(reason.find("no hierarchy"), std::string::npos);
    const auto names = accelerator_names();
    const bool has_bvh = std::find(names.begin(), names.end(), "bvh") != names.end();
    EXPECT_EQ(choose_accelerator(kHandfulOfMembers + 1, reason), has_bvh ? "bvh" : "brute");
    EXPECT_FALSE(reason.empty());
    const Compound many(disjoint_spheres(2, 1));
    EXPECT_EQ(many.accelerator_name(), has_bvh ? "bvh" : "brute");
    EXPECT_EQ(many.accelerator_stats().primitives, 8u);
}

// Union of disjoint spheres through both ways of finding the candidates for spans: box tests
// (8 children) and the structure's all_hits (27 children); the independent answer is the
// distance to the nearest sphere, point membership and the first span end.
TEST(Compound, DisjointSolidsAreASolidWhoseSpansAgreeWithItsHits) {
    for (int per_side : {2, 3}) {
        const Shapes spheres = disjoint_spheres(per_side, 11);
        const Compound compound(spheres);
        ASSERT_TRUE(compound.is_solid());
        const test::PropertyCounts counts = test::check_shape_properties(
            compound, spheres_surface(spheres), 100'000, 21 + per_side);
        EXPECT_GT(counts.hits, 30'000) << per_side;
        EXPECT_GT(counts.span_checks, 300'000) << per_side;
    }
}

TEST(Compound, OverlappingSolidsUniteTheirSpansButShowInnerSurfaces) {
    // Spheres around x = 0 and x = 1.5, radius 1: the union spans [-1, 2.5] along the x axis.
    const Compound compound({sphere(0, 0, 0, 1), sphere(1.5, 0, 0, 1)});
    const Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};
    const SpanList spans = compound.spans(ray);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_DOUBLE_EQ(spans[0].enter.t, 4.0);
    EXPECT_DOUBLE_EQ(spans[0].exit.t, 7.5);
    EXPECT_TRUE(compound.contains(Point3(0.75, 0, 0)));
    EXPECT_FALSE(compound.contains(Point3(2.6, 0, 0)));
    // A plain group: from inside the first sphere, the second's surface at x = 0.5 is hit.
    const auto hit = compound.intersect(Ray{Point3(0, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_DOUBLE_EQ(hit->t, 0.5);
    EXPECT_EQ(hit->object_id, 1u);
}

TEST(Compound, DisjointCompoundIsACsgOperand) {
    // A slab-like ellipsoid minus a compound of 27 disjoint spheres; the independent answer is
    // point membership and the first span end (check_shape_properties on a solid).
    const Shapes holes = disjoint_spheres(3, 3);
    auto ellipsoid = std::make_shared<Instance>(
        std::make_shared<Sphere>(Point3(0, 0, 0), 1.0),
        Transform::translate(Vector3(2, 2, 2)) * Transform::scale(Vector3(3.5, 3.5, 1.2)));
    const Boolean bitten(BooleanOperation::Difference, ellipsoid,
                         std::make_shared<Compound>(holes));
    test::Random random(8);
    long checked = 0;
    for (int i = 0; i < 20'000; ++i) {
        const Aabb region = bitten.bounds();
        const Ray ray = random.ray_between(test::enlarged(region, 0.5), region);
        const SpanList spans = bitten.spans(ray);
        const auto hit = bitten.intersect(ray);
        double first = kInfinity;
        for (const Span& span : spans) {
            if (ray.in_range(span.enter.t)) first = std::min(first, span.enter.t);
            if (ray.in_range(span.exit.t)) first = std::min(first, span.exit.t);
        }
        ASSERT_EQ(hit.has_value(), first < kInfinity) << i;
        if (hit) {
            EXPECT_EQ(hit->t, first) << i;
        }
        for (int sample = 0; sample < 8; ++sample) {
            const double t = random.uniform(0.0, 4.0);
            const Point3 p = ray.at(t);
            bool inside = false, near = false;
            for (const Span& span : spans) {
                if (t > span.enter.t && t < span.exit.t) inside = true;
                if (std::abs(t - span.enter.t) < 1e-9 || std::abs(t - span.exit.t) < 1e-9)
                    near = true;
            }
            if (near) continue;
            const bool expected = ellipsoid->contains(p) &&
                                  std::none_of(holes.begin(), holes.end(),
                                               [&](const auto& s) { return s->contains(p); });
            EXPECT_EQ(inside, expected) << i << " t " << t;
            ++checked;
        }
    }
    EXPECT_GT(checked, 150'000);
}

// The float mesh of the box [lower, upper]: integer_cube(n) scaled onto it. Its corners are
// dyadic for n = 1 and 2, so the float corners are exact and its faces are the box's faces.
std::shared_ptr<const Shape> float_cube(const Point3& lower, const Point3& upper, int n = 1) {
    const test::TestMesh cube = test::integer_cube(n);
    TriangleMeshData data;
    data.triangles = cube.triangles;
    for (const Point3& p : cube.vertices) {
        data.vertices.push_back(lower + (p / n).cwiseProduct(upper - lower));
    }
    auto mesh = std::make_shared<const Mesh>(data);
    EXPECT_TRUE(mesh->is_solid());
    return mesh;
}

// Two cubes sharing the face x = 1, at least one a float mesh, unite in a compound to the box
// [0, 2] x [0, 1]^2 (shifted by `offset`), which a line meets in one interval. The float
// triangle test finds the shared face float ulps away from where the other solid does (a
// double box, or a float mesh whose face is cut into other triangles); the union of their
// spans must merge the two ends within float ulps, as a Boolean over a float mesh does
// (kFloatSpanCoincidence), or it keeps an internal face: a gap between two spans, which the
// complement turns into a sliver of solid. Judged by the exact box: one span, leaving where the
// box does (to 64 float ulps of the coordinates, 2^-18 relative: the float test's error is a
// few ulps), and the complement cut by a larger box is first met where the box is left. With
// the double tolerance Compound had before, the box and the float cube kept a gap on 1,039 and
// 989 of the 2,000 rays (at the origin and 2^11 away) and the shell was hit there; the two
// float cubes merged either way (the float test put their shared face at the same t).
TEST(Compound, SolidsTouchingAFloatMeshUniteWithoutAnInternalFace) {
    for (const Vector3& offset : {Vector3(0, 0, 0), Vector3(1024, -2048, 512)}) {
        const Point3 lower = Point3(0, 0, 0) + offset;
        const Point3 middle = lower + Vector3(1, 1, 1), far = lower + Vector3(2, 1, 1);
        const Point3 shared = lower + Vector3(1, 0, 0);
        for (const Shapes& pair :
             {Shapes{float_cube(lower, middle, 1), float_cube(shared, far, 2)},
              Shapes{std::make_shared<const Box>(lower, middle), float_cube(shared, far, 1)}}) {
            auto compound = std::make_shared<const Compound>(pair);
            ASSERT_TRUE(compound->is_solid());
            const Box exact(lower, lower + Vector3(2, 1, 1));
            // The complement of the compound inside a box around it: the shell between the two.
            const Boolean shell(
                BooleanOperation::Intersection,
                std::make_shared<const Box>(lower - Vector3(1, 1, 1), lower + Vector3(3, 2, 2)),
                std::make_shared<const Complement>(compound));
            test::Random random(29);
            int gaps = 0, wrong_hits = 0;
            for (int i = 0; i < 2'000; ++i) {
                // From inside the first cube, through the shared face, to the far face x = 2.
                const Point3 origin =
                    lower + Vector3(random.uniform(0.05, 0.95), random.uniform(0.05, 0.95),
                                    random.uniform(0.05, 0.95));
                const Point3 target =
                    lower + Vector3(2.0, random.uniform(0.05, 0.95), random.uniform(0.05, 0.95));
                const Ray ray{origin, target - origin};
                const SpanList exact_spans = exact.spans(ray);
                ASSERT_EQ(exact_spans.size(), 1u);
                const double scale =
                    ray.origin.cwiseAbs().maxCoeff() / ray.direction.cwiseAbs().maxCoeff();
                const auto close = [&](double t, double expected) {
                    return std::abs(t - expected) <= 0x1.0p-18 * (std::abs(expected) + scale);
                };
                const SpanList spans = compound->spans(ray);
                gaps += spans.size() != 1u;
                if (spans.size() == 1u) {
                    // The entry lies behind the origin, outside [t_min, t_max]: only its side is
                    // defined (Shape::find_spans).
                    EXPECT_LE(spans[0].enter.t, ray.t_min) << i;
                    EXPECT_TRUE(close(spans[0].exit.t, exact_spans[0].exit.t)) << i;
                }
                // The shell's nearest hit from inside the compound is where the ray leaves it.
                const auto hit = shell.intersect(ray);
                wrong_hits += !hit || !close(hit->t, exact_spans[0].exit.t);
            }
            EXPECT_EQ(gaps, 0) << offset.transpose() << " " << pair[0]->kind();
            EXPECT_EQ(wrong_hits, 0) << offset.transpose() << " " << pair[0]->kind();
        }
    }
}

// The compound's structure against brute force and a hand-made hierarchy of compounds: the
// same hit bit for bit (t, leaf, primitive), and the same occlusion.
TEST(Compound, StructuresAndHierarchiesGiveTheSameHitsAsBruteForce) {
    test::Random random(17);
    Shapes spheres;
    for (int i = 0; i < 1000; ++i) {
        spheres.push_back(sphere(random.uniform(-50, 50), random.uniform(-50, 50),
                                 random.uniform(-50, 50), random.uniform(0.2, 3.0)));
    }
    spheres.push_back(test::ground_plane());
    const Compound brute(spheres, test::structure_named<CompoundConfig>("brute"));
    const Compound automatic(spheres);
    const auto hierarchy = make_hierarchy(spheres, 4);
    const auto binary = make_hierarchy(spheres, 2);
    const Aabb region(Point3(-60, -60, -60), Point3(60, 60, 60));
    int hits = 0;
    for (int i = 0; i < 10'000; ++i) {
        Ray ray = random.ray_between(region, region);
        if (i % 3 == 0) ray.t_max = random.uniform(0.0, 2.0);
        const auto expected = brute.intersect(ray);
        hits += expected.has_value();
        for (const Shape* shape :
             {static_cast<const Shape*>(&automatic), hierarchy.get(), binary.get()}) {
            const auto actual = shape->intersect(ray);
            ASSERT_EQ(actual.has_value(), expected.has_value()) << i;
            EXPECT_EQ(shape->occluded(ray), expected.has_value()) << i;
            if (!expected) continue;
            EXPECT_EQ(actual->t, expected->t) << i;
            EXPECT_EQ(actual->shape, expected->shape) << i;
            EXPECT_EQ(actual->primitive_id, expected->primitive_id) << i;
        }
        EXPECT_EQ(automatic.intersect(ray).value_or(Hit{}).object_id,
                  expected.value_or(Hit{}).object_id);
    }
    EXPECT_GT(hits, 4000);
}

TEST(Compound, HierarchyTestsFarFewerChildren) {
    std::atomic<long> calls{0};
    Shapes counted;
    for (const auto& s : disjoint_spheres(12, 4))
        counted.push_back(std::make_shared<Counted>(s, calls));
    const Compound flat(counted, test::structure_named<CompoundConfig>("brute"));
    const auto hierarchy = make_hierarchy(counted, 4);
    test::Random random(2);
    const Aabb region(Point3(-1, -1, -1), Point3(23, 23, 23));
    long flat_calls = 0, hierarchy_calls = 0;
    for (int i = 0; i < 2000; ++i) {
        const Ray ray = random.ray_between(test::enlarged(region, 0.5), region);
        calls = 0;
        const auto expected = flat.intersect(ray);
        flat_calls += calls;
        calls = 0;
        const auto actual = hierarchy->intersect(ray);
        hierarchy_calls += calls;
        ASSERT_EQ(actual.has_value(), expected.has_value());
        if (expected) {
            EXPECT_EQ(actual->t, expected->t);
        }
    }
    // 1728 children per ray by brute force; a ray crosses about 12-24 cells of the 12^3 grid,
    // and the hierarchy asks only children whose box it meets: measured 19.4 per ray.
    EXPECT_GT(flat_calls, 1728L * 1900);
    EXPECT_LT(hierarchy_calls * 50, flat_calls);
    std::printf("children asked per ray: flat %.1f, hierarchy %.1f\n", flat_calls / 2000.0,
                hierarchy_calls / 2000.0);
}

// The 10,000-object CSG scene shipped in data/scenes: the same hits through a hierarchy of
// compounds (and through the scene's own structure) as by brute force, with at least 50x fewer
// objects tested per ray. Objects are all instances of one difference node, so hits are
// compared by t and by the finished point and normal, which differ from object to object.
TEST(Compound, TenThousandObjectSceneHierarchyMatchesBruteForceWithFarFewerTests) {
    Scene brute = load_scene(std::filesystem::path(CSGRT_SOURCE_DIR) / "data" / "scenes" /
                             "csg_grid_10000.json");
    ASSERT_EQ(brute.objects().size(), 10'001u);
    Scene automatic = brute;
    SceneConfig config;
    config.accelerator = "brute";
    brute.commit(config);
    automatic.commit();

    std::atomic<long> calls{0};
    Shapes counted;
    for (const SceneObject& object : brute.objects()) {
        counted.push_back(std::make_shared<Counted>(object.shape, calls));
    }
    const auto hierarchy = make_hierarchy(counted, 4);

    test::Random random(10'000);
    const Aabb region(Point3(-51, -1, -51), Point3(51, 2, 51));
    QueryScratch scratch;
    TraversalCounters brute_counters, automatic_counters;
    long hierarchy_calls = 0;
    int hits = 0;
    // Label "heavy": test::scaled() of the rays under the sanitizers.
    const int ray_count = test::scaled(10'000);
    for (int i = 0; i < ray_count; ++i) {
        // Half camera rays over the whole film, half random rays through the grid's slab.
        const Ray ray =
            i % 2 ? brute.camera().generate_ray(random.uniform(), random.uniform(), 16.0 / 9.0)
                  : random.ray_between(test::enlarged(region, 0.2), region);
        const auto expected = brute.intersect_counted(ray, scratch, brute_counters);
        const auto actual = automatic.intersect_counted(ray, scratch, automatic_counters);
        calls = 0;
        const auto grouped = hierarchy->intersect(ray);
        hierarchy_calls += calls;
        ASSERT_EQ(actual.has_value(), expected.has_value()) << i;
        ASSERT_EQ(grouped.has_value(), expected.has_value()) << i;
        EXPECT_EQ(automatic.occluded(ray, scratch), expected.has_value()) << i;
        if (!expected) continue;
        ++hits;
        EXPECT_EQ(actual->t, expected->t) << i;
        EXPECT_EQ(actual->object_id, expected->object_id) << i;
        EXPECT_EQ(actual->point, expected->point) << i;
        EXPECT_EQ(grouped->t, expected->t) << i;
        EXPECT_EQ(grouped->point, expected->point) << i;
        EXPECT_EQ(grouped->geometric_normal, expected->geometric_normal) << i;
        EXPECT_EQ(grouped->shape, expected->shape) << i;
    }
    EXPECT_GT(hits, ray_count / 2);
    // Brute force tests all 10,001 objects (the ground included) on every ray.
    EXPECT_EQ(brute_counters.primitives_tested, 10'001u * static_cast<unsigned>(ray_count));
    const double brute_per_ray = double(brute_counters.primitives_tested) / ray_count;
    const double hierarchy_per_ray = double(hierarchy_calls) / ray_count;
    const double automatic_per_ray = double(automatic_counters.primitives_tested) / ray_count;
    std::printf(
        "objects tested per ray: brute %.0f, hierarchy of compounds %.1f, scene's %s %.1f "
        "(%.1f nodes, %.1f boxes)\n",
        brute_per_ray, hierarchy_per_ray, std::string(automatic.accelerator_name()).c_str(),
        automatic_per_ray, double(automatic_counters.nodes_visited) / ray_count,
        double(automatic_counters.boxes_tested) / ray_count);
    EXPECT_GT(brute_per_ray, 50.0 * hierarchy_per_ray);
    // The scene's own "auto" choice over 10,001 objects is the BVH.
    EXPECT_EQ(automatic.accelerator_name(), "bvh");
    EXPECT_GT(brute_per_ray, 50.0 * automatic_per_ray);
}

}  // namespace
}  // namespace csgrt
