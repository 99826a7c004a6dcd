#include "csgrt/csg/boolean.h"

#include <gtest/gtest.h>

#include <atomic>

#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/sphere.h"
#include "support/leaf_checks.h"
#include "support/random.h"
#include "support/shape_properties.h"

namespace csgrt {
namespace {

// Test fixture, not part of the library: the solid axis-aligned box [lower, upper], for the
// shared-face cases until the library's own box lands. Every face's t is (plane - o) / d, so
// two boxes that share a plane compute bit-identical t there, as real coincident faces do.
class TestBox final : public Shape {
public:
    TestBox(const Point3& lower, const Point3& upper) : box_(lower, upper) {}

    std::string_view kind() const override { return "test_box"; }
    Aabb bounds() const override { return box_; }
    bool is_solid() const override { return true; }

    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch&) const override {
        Span span;
        if (!line_span(ray, span)) return false;
        const HitRecord& end = ray.in_range(span.enter.t) ? span.enter : span.exit;
        if (!ray.in_range(end.t)) return false;
        record = end;
        return true;
    }
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override {
        HitRecord record;
        return nearest_hit(ray, record, scratch);
    }
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch&) const override {
        spans.clear();
        Span span;
        if (line_span(ray, span) && !(span.exit.t < ray.t_min) && !(span.enter.t > ray.t_max))
            spans.push_back(span);
    }
    bool contains(const Point3& p) const override {
        return (p.array() > box_.lower.array()).all() && (p.array() < box_.upper.array()).all();
    }
    Hit finish(const Ray& ray, const HitRecord& record) const override {
        Hit hit;
        hit.t = record.t;
        hit.point = ray.at(record.t);
        hit.geometric_normal = Normal3::Zero();
        hit.geometric_normal[record.primitive / 2] = record.primitive % 2 ? 1.0 : -1.0;
        hit.shading_normal = hit.geometric_normal;
        hit.shape = this;
        hit.primitive_id = record.primitive;
        hit.front_face = ray.direction.dot(hit.geometric_normal) < 0.0;
        return hit;
    }

private:
    // The line's entry and exit through the slabs; face 2 axis + 1 is the upper side.
    bool line_span(const Ray& ray, Span& span) const {
        double t0 = -kInfinity, t1 = kInfinity;
        std::uint32_t face0 = kNoIndex, face1 = kNoIndex;
        for (std::uint32_t axis = 0; axis < 3; ++axis) {
            const double o = ray.origin[axis], d = ray.direction[axis];
            if (d == 0.0) {
                if (o < box_.lower[axis] || o > box_.upper[axis]) return false;
                continue;
            }
            double near = (box_.lower[axis] - o) / d, far = (box_.upper[axis] - o) / d;
            std::uint32_t near_face = 2 * axis, far_face = 2 * axis + 1;
            if (near > far) {
                std::swap(near, far);
                std::swap(near_face, far_face);
            }
            if (near > t0) t0 = near, face0 = near_face;
            if (far < t1) t1 = far, face1 = far_face;
        }
        if (!(t0 <= t1)) return false;
        span = Span{HitRecord{.t = t0, .shape = this, .primitive = face0},
                    HitRecord{.t = t1, .shape = this, .primitive = face1}};
        return true;
    }

    Aabb box_;
};

// Test fixture: a non-solid shape (an infinitely thin square) for the operand checks.
class FlatSquare final : public Shape {
public:
    std::string_view kind() const override { return "flat_square"; }
    Aabb bounds() const override { return Aabb(Point3(-1, -1, 0), Point3(1, 1, 0)); }
    bool nearest_hit(const Ray&, HitRecord&, QueryScratch&) const override { return false; }
    bool any_hit(const Ray&, QueryScratch&) const override { return false; }
};

// Test fixture: forwards to a solid and counts the queries it is asked, to show what a node
// skips.
class CountingShape final : public Shape {
public:
    explicit CountingShape(std::shared_ptr<const Shape> shape) : shape_(std::move(shape)) {}
    std::string_view kind() const override { return shape_->kind(); }
    Aabb bounds() const override { return shape_->bounds(); }
    bool is_solid() const override { return true; }
    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override {
        ++calls;
        return shape_->nearest_hit(ray, record, scratch);
    }
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override {
        ++calls;
        return shape_->any_hit(ray, scratch);
    }
    void find_spans(const Ray& ray, SpanList& spans, QueryScratch& scratch) const override {
        ++calls;
        ++span_calls;
        shape_->find_spans(ray, spans, scratch);
    }
    bool contains(const Point3& p) const override { return shape_->contains(p); }

    mutable std::atomic<int> calls = 0;
    mutable std::atomic<int> span_calls = 0;

private:
    std::shared_ptr<const Shape> shape_;
};

std::shared_ptr<const Shape> sphere(const Point3& center, double radius) {
    return std::make_shared<Sphere>(center, radius);
}
std::shared_ptr<const Shape> box(const Point3& lower, const Point3& upper) {
    return std::make_shared<TestBox>(lower, upper);
}
std::shared_ptr<const Boolean> boolean(BooleanOperation operation,
                                       std::shared_ptr<const Shape> first,
                                       std::shared_ptr<const Shape> second) {
    return std::make_shared<Boolean>(operation, std::move(first), std::move(second));
}

constexpr auto kUnion = BooleanOperation::Union;
constexpr auto kIntersection = BooleanOperation::Intersection;
constexpr auto kDifference = BooleanOperation::Difference;

bool normal_is(const Hit& hit, const Normal3& expected) {
    return (hit.geometric_normal - expected).norm() < 1e-12;
}

TEST(Boolean, RejectsMissingAndNonSolidOperands) {
    const auto ball = sphere(Point3(0, 0, 0), 1);
    const auto square = std::make_shared<FlatSquare>();
    try {
        Boolean(kDifference, ball, square);
        FAIL() << "a non-solid operand was accepted";
    } catch (const InvalidParameter& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("second operand"), std::string::npos) << message;
        EXPECT_NE(message.find("flat_square"), std::string::npos) << message;
        EXPECT_NE(message.find("difference"), std::string::npos) << message;
    }
    EXPECT_THROW(Boolean(kUnion, square, ball), InvalidParameter);
    EXPECT_THROW(Boolean(kUnion, nullptr, ball), InvalidParameter);
    EXPECT_THROW(Boolean(kIntersection, ball, nullptr), InvalidParameter);
    EXPECT_THROW(make_union({}), InvalidParameter);
    try {
        make_intersection({ball, ball, square});
        FAIL() << "a non-solid operand was accepted";
    } catch (const InvalidParameter& error) {
        EXPECT_NE(std::string(error.what()).find("operands[2]"), std::string::npos);
    }
    EXPECT_THROW(make_difference(square, {ball}), InvalidParameter);
    // An instance of a solid is a solid operand; an instance of a flat shape is not.
    EXPECT_NO_THROW(Boolean(kUnion, ball, std::make_shared<Instance>(ball, Transform::scale(2))));
    EXPECT_THROW(Boolean(kUnion, ball, std::make_shared<Instance>(square, Transform())),
                 InvalidParameter);
}

TEST(Boolean, KindAndBoundsFollowTheOperation) {
    const auto a = sphere(Point3(0, 0, 0), 1);
    const auto b = sphere(Point3(1.5, 0, 0), 1);
    const Boolean union_node(kUnion, a, b), intersection(kIntersection, a, b),
        difference(kDifference, a, b);
    EXPECT_EQ(union_node.kind(), "union");
    EXPECT_EQ(intersection.kind(), "intersection");
    EXPECT_EQ(difference.kind(), "difference");
    EXPECT_TRUE(union_node.is_solid());
    EXPECT_EQ(union_node.bounds().lower, Point3(-1, -1, -1));
    EXPECT_EQ(union_node.bounds().upper, Point3(2.5, 1, 1));
    EXPECT_EQ(intersection.bounds().lower, Point3(0.5, -1, -1));
    EXPECT_EQ(intersection.bounds().upper, Point3(1, 1, 1));
    EXPECT_EQ(difference.bounds().lower, Point3(-1, -1, -1));
    EXPECT_EQ(difference.bounds().upper, Point3(1, 1, 1));
    // Disjoint operands intersect in nothing, and the empty box culls every ray.
    const Boolean nothing(kIntersection, a, sphere(Point3(5, 0, 0), 1));
    EXPECT_TRUE(nothing.bounds().is_empty());
    EXPECT_FALSE(nothing.intersect(Ray{Point3(-10, 0, 0), Vector3(1, 0, 0)}));
    EXPECT_TRUE(nothing.spans(Ray{Point3(-10, 0, 0), Vector3(1, 0, 0)}).empty());
}

TEST(Boolean, AnalyticUnionIntersectionAndDifference) {
    // Unit sphere at the origin and a sphere of radius 0.5 at x = 1: along the x axis the first
    // covers [-1, 1], the second [0.5, 1.5].
    const auto a = sphere(Point3(0, 0, 0), 1);
    const auto b = sphere(Point3(1, 0, 0), 0.5);
    const Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};
    const Boolean union_node(kUnion, a, b), lens(kIntersection, a, b), bite(kDifference, a, b);

    std::optional<Hit> hit = union_node.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.0);
    EXPECT_EQ(hit->shape, a.get());
    SpanList spans = union_node.spans(ray);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].exit.t, 6.5);
    EXPECT_EQ(spans[0].exit.shape, b.get());

    hit = lens.intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 5.5);
    EXPECT_EQ(hit->shape, b.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(-1, 0, 0)));  // b's own outward normal: not flipped

    // From +x, the bite: the first surface is b's, flipped to point out of the material (+x).
    const Ray from_right{Point3(5, 0, 0), Vector3(-1, 0, 0)};
    hit = bite.intersect(from_right);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 4.5);
    EXPECT_EQ(hit->shape, b.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(1, 0, 0)));
    EXPECT_TRUE(hit->front_face);
    EXPECT_TRUE(hit->point.isApprox(Point3(0.5, 0, 0)));
    spans = bite.spans(ray);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, 4.0);
    EXPECT_EQ(spans[0].exit.t, 5.5);
    EXPECT_TRUE(spans[0].exit.flip_normal);
}

TEST(Boolean, HollowSphereShowsTheCavityWallFacingIntoTheCavity) {
    const auto outer = sphere(Point3(0, 0, 0), 2);
    const auto inner = sphere(Point3(0, 0, 0), 1);
    const Boolean shell(kDifference, outer, inner);
    // From outside: the outer surface, outward.
    std::optional<Hit> hit = shell.intersect(Ray{Point3(0, 0, -5), Vector3(0, 0, 1)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->shape, outer.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(0, 0, -1)));
    // From within the material toward the centre: the cavity wall, whose normal points into
    // the cavity (out of the material); the ray leaves the material, so it is a back face.
    hit = shell.intersect(Ray{Point3(0, 0, -1.5), Vector3(0, 0, 1)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 0.5);
    EXPECT_EQ(hit->shape, inner.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(0, 0, 1)));
    EXPECT_FALSE(hit->front_face);
    // From inside the cavity: the same wall, now entered from the front.
    hit = shell.intersect(Ray{Point3(0, 0, 0), Vector3(0, 0, 1)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 1.0);
    EXPECT_EQ(hit->shape, inner.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(0, 0, -1)));
    EXPECT_TRUE(hit->front_face);
    EXPECT_FALSE(shell.contains(Point3(0, 0, 0.5)));
    EXPECT_TRUE(shell.contains(Point3(0, 0, 1.5)));
}

TEST(Boolean, NestedDifferencesFlipTwiceAndInstancesMapNormals) {
    // big - (cavity - core): a spherical shell of air around a core that stays material.
    const auto big = sphere(Point3(0, 0, 0), 3);
    const auto cavity = sphere(Point3(0, 0, 0), 2);
    const auto core = sphere(Point3(0, 0, 0), 1);
    const auto solid = boolean(kDifference, big, boolean(kDifference, cavity, core));
    const Ray ray{Point3(0, 0, -2.5), Vector3(0, 0, 1)};  // starts in the outer material
    std::optional<Hit> hit = solid->intersect(ray);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->shape, cavity.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(0, 0, 1)));  // flipped once: into the air gap
    Ray onward = ray;
    onward.t_min = 1.0;
    hit = solid->intersect(onward);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 1.5);
    EXPECT_EQ(hit->shape, core.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(0, 0, -1)));  // flipped twice: the core's own outward
    EXPECT_TRUE(hit->front_face);

    // The bite, stretched by 2 along x and moved by 10 along z: normals map by the inverse
    // transpose after the flip, hits still name the leaf.
    const auto b = sphere(Point3(1, 0, 0), 0.5);
    const Instance placed(
        boolean(kDifference, sphere(Point3(0, 0, 0), 1), b),
        Transform::translate(Vector3(0, 0, 10)) * Transform::scale(Vector3(2, 1, 1)));
    hit = placed.intersect(Ray{Point3(5, 0, 10), Vector3(-1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 4.0, 1e-15);  // the bite's surface at object x = 0.5, world x = 1
    EXPECT_EQ(hit->shape, b.get());
    EXPECT_TRUE(normal_is(*hit, Normal3(1, 0, 0)));
    EXPECT_TRUE(hit->front_face);
}

TEST(Boolean, IntervalHonouredAtBothEndsAndRaysFromInside) {
    const auto a = sphere(Point3(0, 0, 0), 1);
    const auto b = sphere(Point3(1, 0, 0), 0.5);
    const Boolean bite(kDifference, a, b);
    const Ray ray{Point3(-5, 0, 0), Vector3(1, 0, 0)};  // material on [4, 5.5]; a exits at 6
    auto first_t = [&](double t_min, double t_max) -> std::optional<double> {
        Ray clipped = ray;
        clipped.t_min = t_min;
        clipped.t_max = t_max;
        const std::optional<Hit> hit = bite.intersect(clipped);
        EXPECT_EQ(bite.occluded(clipped), hit.has_value()) << t_min << " " << t_max;
        return hit ? std::optional<double>(hit->t) : std::nullopt;
    };
    EXPECT_EQ(first_t(0, kInfinity), 4.0);
    EXPECT_EQ(first_t(0, 4.0), 4.0);
    EXPECT_EQ(first_t(0, std::nextafter(4.0, 0.0)), std::nullopt);
    EXPECT_EQ(first_t(4.0, 4.0), 4.0);
    EXPECT_EQ(first_t(std::nextafter(4.0, 5.0), kInfinity), 5.5);
    EXPECT_EQ(first_t(4.5, 5.5), 5.5);
    EXPECT_EQ(first_t(4.5, std::nextafter(5.5, 0.0)), std::nullopt);
    // a's exit at 6 lies inside b: never a surface of the result.
    EXPECT_EQ(first_t(5.6, kInfinity), std::nullopt);
    EXPECT_EQ(first_t(-kInfinity, kInfinity), 4.0);

    // From inside the material: the nearer of the bite (+x) and a's far side (-x).
    std::optional<Hit> hit = bite.intersect(Ray{Point3(0, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 0.5);
    EXPECT_FALSE(hit->front_face);
    hit = bite.intersect(Ray{Point3(0, 0, 0), Vector3(-2, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 0.5);
    EXPECT_EQ(hit->shape, a.get());
    const SpanList spans = bite.spans(Ray{Point3(0, 0, 0), Vector3(1, 0, 0)});
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, -1.0);  // the span that began behind the origin is kept
}

TEST(Boolean, InvalidRaysNeverHit) {
    const Boolean bite(kDifference, sphere(Point3(0, 0, 0), 1), sphere(Point3(1, 0, 0), 0.5));
    test::expect_invalid_rays_miss(bite, Ray{Point3(0, 0, -5), Vector3(0, 0, 1)});
}

TEST(Boolean, SkipsWhatTheRayDoesNotNeed) {
    auto counted = [](const Point3& center) {
        return std::make_shared<CountingShape>(sphere(center, 1));
    };
    auto reset = [](std::initializer_list<const CountingShape*> shapes) {
        for (const CountingShape* shape : shapes) shape->calls = shape->span_calls = 0;
    };
    const auto a = counted(Point3(0, 0, 0));
    const auto b = counted(Point3(0.5, 0, 0));
    // Through the overlap box (x in [-0.5, 1]) but outside a: a is asked once, b never.
    const Ray misses_a{Point3(0.9, 0.9, -5), Vector3(0, 0, 1)};
    for (BooleanOperation operation : {kIntersection, kDifference}) {
        const Boolean node(operation, a, b);
        reset({a.get(), b.get()});
        EXPECT_FALSE(node.intersect(misses_a));
        EXPECT_FALSE(node.occluded(misses_a));
        EXPECT_TRUE(node.spans(misses_a).empty());
        EXPECT_EQ(a->calls, 3);
        EXPECT_EQ(b->calls, 0) << "operation " << static_cast<int>(operation);
    }
    // A ray that misses the node's box asks nobody.
    const Ray far_away{Point3(10, 10, -5), Vector3(0, 0, 1)};
    for (BooleanOperation operation : {kUnion, kIntersection, kDifference}) {
        const Boolean node(operation, a, b);
        reset({a.get(), b.get()});
        EXPECT_FALSE(node.intersect(far_away));
        EXPECT_FALSE(node.occluded(far_away));
        EXPECT_TRUE(node.spans(far_away).empty());
        EXPECT_EQ(a->calls + b->calls, 0);
    }
    // A difference whose subtracted operand's box the ray misses is its first operand.
    const auto c = counted(Point3(0, 5, 0));
    const Boolean difference(kDifference, a, c);
    reset({a.get(), c.get()});
    EXPECT_TRUE(difference.intersect(Ray{Point3(0, 0, -5), Vector3(0, 0, 1)}));
    EXPECT_EQ(a->span_calls, 0);
    EXPECT_EQ(c->calls, 0);
    // A union of operands whose boxes lie one after the other along the ray: no span lists,
    // and the farther operand is not asked when the nearer one is hit.
    const auto left = counted(Point3(-3, 0, 0));
    const auto right = counted(Point3(3, 0, 0));
    const Boolean pair(kUnion, left, right);
    for (const Ray& ray :
         {Ray{Point3(-10, 0, 0), Vector3(1, 0, 0)}, Ray{Point3(10, 0, 0), Vector3(-1, 0, 0)}}) {
        reset({left.get(), right.get()});
        const std::optional<Hit> hit = pair.intersect(ray);
        ASSERT_TRUE(hit);
        EXPECT_EQ(hit->t, 6.0);
        EXPECT_TRUE(pair.occluded(ray));
        EXPECT_EQ(left->span_calls + right->span_calls, 0);
        EXPECT_EQ(left->calls + right->calls, 2);
    }
    // Overlapping boxes need the span lists: a's hit at -1 is inside b.
    const auto wide = counted(Point3(-1, 0, 0));
    const Boolean overlapping(kUnion, a, wide);
    reset({a.get(), wide.get()});
    const std::optional<Hit> hit = overlapping.intersect(Ray{Point3(-10, 0, 0), Vector3(1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 8.0);
    EXPECT_EQ(a->span_calls + wide->span_calls, 2);
}

TEST(Boolean, MakeHelpersBuildBalancedTrees) {
    std::vector<std::shared_ptr<const Shape>> balls;
    for (int i = 0; i < 5; ++i) balls.push_back(sphere(Point3(3.0 * i, 0, 0), 1));
    const auto row = make_union(balls);
    ASSERT_EQ(row->kind(), "union");
    const auto& root = static_cast<const Boolean&>(*row);
    EXPECT_EQ(root.first().kind(), "union");  // 2 + 3, not a chain of four
    EXPECT_EQ(root.second().kind(), "union");
    EXPECT_EQ(make_union({balls[0]}), balls[0]);
    const std::optional<Hit> hit = row->intersect(Ray{Point3(20, 0, 0), Vector3(-1, 0, 0)});
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 7.0);
    EXPECT_EQ(hit->shape, balls[4].get());
    // A block minus three balls: what is left along a line through all of them.
    const auto slab = box(Point3(-2, -2, -2), Point3(8, 2, 2));
    const auto holes = make_difference(slab, {balls[0], balls[1], balls[2]});
    EXPECT_EQ(make_difference(slab, {}), slab);
    const SpanList spans = holes->spans(Ray{Point3(-10, 0, 0), Vector3(1, 0, 0)});
    ASSERT_EQ(spans.size(), 4u);
    EXPECT_EQ(spans[0].enter.t, 8.0);
    EXPECT_EQ(spans[0].exit.t, 9.0);
    EXPECT_EQ(spans[3].enter.t, 17.0);
    EXPECT_EQ(spans[3].exit.t, 18.0);
    const auto lens = make_intersection({balls[0], sphere(Point3(1, 0, 0), 1)});
    EXPECT_EQ(lens->intersect(Ray{Point3(-10, 0, 0), Vector3(1, 0, 0)})->t, 10.0);
}

// The coincident and touching cases of docs/csg.md.

TEST(BooleanCoincident, SolidMinusItselfIsEmpty) {
    const auto ball = sphere(Point3(0.2, -0.1, 0.3), 1.3);
    const auto ellipsoid = std::make_shared<Instance>(
        ball, Transform::rotate(Vector3(1, 2, 3), 0.7) * Transform::scale(Vector3(1, 2, 0.5)));
    test::Random random(41);
    for (const std::shared_ptr<const Shape>& solid :
         std::initializer_list<std::shared_ptr<const Shape>>{ball, ellipsoid}) {
        const Boolean nothing(kDifference, solid, solid);
        const Boolean same_union(kUnion, solid, solid),
            same_intersection(kIntersection, solid, solid);
        int solid_hits = 0;
        for (int i = 0; i < 20000; ++i) {
            Ray ray = test::ray_toward(random, solid->bounds(), i);
            ASSERT_FALSE(nothing.intersect(ray)) << "speckle, ray " << i;
            ASSERT_FALSE(nothing.occluded(ray));
            ASSERT_TRUE(nothing.spans(ray).empty());
            // A u A and A n A are A, hit for hit.
            const std::optional<Hit> expected = solid->intersect(ray);
            solid_hits += expected.has_value();
            for (const Boolean* same : {&same_union, &same_intersection}) {
                const std::optional<Hit> hit = same->intersect(ray);
                ASSERT_EQ(hit.has_value(), expected.has_value()) << "ray " << i;
                if (hit) {
                    ASSERT_EQ(hit->t, expected->t);
                    ASSERT_EQ(hit->geometric_normal, expected->geometric_normal);
                }
            }
        }
        EXPECT_GT(solid_hits, 5000);
    }
}

TEST(BooleanCoincident, SameSphereComputedTwoWaysIsOneSurface) {
    // The sphere of radius 1.3 at c as a Sphere and as a scaled, moved unit sphere: the roots
    // differ by rounding, which the coincidence tolerance absorbs except at grazing incidence.
    const Point3 center(0.2, -0.1, 0.3);
    const auto direct = sphere(center, 1.3);
    const auto instanced = std::make_shared<Instance>(
        sphere(Point3(0, 0, 0), 1), Transform::translate(center) * Transform::scale(1.3));
    const Boolean nothing(kDifference, direct, instanced);
    const Boolean nothing_reversed(kDifference, instanced, direct);
    test::Random random(43);
    int steep = 0;
    for (int i = 0; i < 50000; ++i) {
        Ray ray = test::ray_toward(random, direct->bounds(), i);
        const std::optional<Hit> hit = direct->intersect(ray);
        // Incidence within about 4 degrees of grazing (|cos| < 1/16) is outside the
        // tolerance's slope budget (span_combine.h).
        if (!hit || std::abs(hit->geometric_normal.dot(ray.direction.normalized())) < 1.0 / 16)
            continue;
        ++steep;
        ASSERT_FALSE(nothing.intersect(ray)) << "speckle, ray " << i;
        ASSERT_FALSE(nothing_reversed.intersect(ray)) << "speckle, ray " << i;
    }
    EXPECT_GT(steep, 20000);
}

TEST(BooleanCoincident, BoxesSharingAFaceUniteWithoutAnInternalSurface) {
    const auto left = box(Point3(0, 0, 0), Point3(1, 1, 1));
    const auto right = box(Point3(1, 0, 0), Point3(2, 1, 1));
    const TestBox whole(Point3(0, 0, 0), Point3(2, 1, 1));
    const Boolean joined(kUnion, left, right);
    const Boolean touching(kIntersection, left, right);
    const Boolean left_again(kDifference, box(Point3(0, 0, 0), Point3(2, 1, 1)), right);
    const Boolean untouched(kDifference, right, left);
    test::Random random(47);
    int crossings = 0;
    for (int i = 0; i < 20000; ++i) {
        Ray ray = random.ray_between(test::enlarged(whole.bounds(), 1.0), whole.bounds());
        if (i % 3 == 0) ray.origin = random.in_box(whole.bounds());  // often inside, at the face
        const std::optional<Hit> expected = whole.intersect(ray);
        const std::optional<Hit> hit = joined.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected.has_value()) << "ray " << i;
        if (hit) {
            ASSERT_EQ(hit->t, expected->t) << "internal surface, ray " << i;
            ASSERT_EQ(hit->geometric_normal, expected->geometric_normal);
        }
        const SpanList spans = joined.spans(ray);
        ASSERT_LE(spans.size(), 1u);
        // Rays from inside the left box that leave through the right one cross the shared face.
        crossings += expected && ray.origin.x() < 1 && expected->point.x() > 1;
        // Touching solids intersect in nothing.
        ASSERT_FALSE(touching.intersect(ray)) << "ray " << i;
        ASSERT_TRUE(touching.spans(ray).empty());
        // whole - right is left, whose x = 1 face is right's, flipped; right - left is right.
        for (const auto& [node, reference] :
             {std::pair<const Boolean*, const Shape*>{&left_again, left.get()},
              std::pair<const Boolean*, const Shape*>{&untouched, right.get()}}) {
            const std::optional<Hit> cut = node->intersect(ray);
            const std::optional<Hit> reference_hit = reference->intersect(ray);
            ASSERT_EQ(cut.has_value(), reference_hit.has_value()) << "ray " << i;
            if (cut) {
                ASSERT_EQ(cut->t, reference_hit->t) << "ray " << i;
                ASSERT_EQ(cut->geometric_normal, reference_hit->geometric_normal) << "ray " << i;
                ASSERT_EQ(cut->front_face, reference_hit->front_face);
            }
        }
    }
    EXPECT_GT(crossings, 1000);
}

TEST(BooleanCoincident, CutExactlyAtTheCapKeepsOneSurface) {
    // A block minus its own upper half (sharing the top and four side faces) is the lower half;
    // a block minus a slab resting on its top is the block, its top still its own face.
    const auto block = box(Point3(0, 0, 0), Point3(1, 1, 1));
    const TestBox lower_half(Point3(0, 0, 0), Point3(1, 0.5, 1));
    const auto upper_half = box(Point3(0, 0.5, 0), Point3(1, 1, 1));
    const auto resting = box(Point3(-1, 1, -1), Point3(2, 2, 2));
    const Boolean cut(kDifference, block, upper_half);
    const Boolean capped(kDifference, block, resting);
    test::Random random(53);
    int top_hits = 0;
    for (int i = 0; i < 20000; ++i) {
        Ray ray = test::ray_toward(random, block->bounds(), i);
        const std::optional<Hit> expected = lower_half.intersect(ray);
        const std::optional<Hit> hit = cut.intersect(ray);
        ASSERT_EQ(hit.has_value(), expected.has_value()) << "ray " << i;
        if (hit) {
            ASSERT_EQ(hit->t, expected->t) << "ray " << i;
            ASSERT_EQ(hit->geometric_normal, expected->geometric_normal) << "ray " << i;
        }
        const std::optional<Hit> block_hit = block->intersect(ray);
        const std::optional<Hit> capped_hit = capped.intersect(ray);
        ASSERT_EQ(capped_hit.has_value(), block_hit.has_value());
        if (capped_hit) {
            ASSERT_EQ(capped_hit->t, block_hit->t);
            ASSERT_EQ(capped_hit->shape, block.get()) << "the resting slab's face won, ray " << i;
            top_hits += capped_hit->primitive_id == 3;
        }
    }
    EXPECT_GT(top_hits, 500);
}

TEST(BooleanCoincident, SpheresTouchingAtAPoint) {
    const auto a = sphere(Point3(0, 0, 0), 1);
    const auto b = sphere(Point3(2, 0, 0), 1);
    const Boolean pair(kUnion, a, b);
    const Boolean touch(kIntersection, a, b);
    // Along the line of centres from inside a: one span, the contact point is no surface.
    const Ray through{Point3(-0.5, 0, 0), Vector3(1, 0, 0)};
    const SpanList spans = pair.spans(through);
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.t, -0.5);
    EXPECT_EQ(spans[0].exit.t, 3.5);
    const std::optional<Hit> hit = pair.intersect(through);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 3.5);
    EXPECT_EQ(hit->shape, b.get());
    // The intersection is the single contact point: empty once regularised.
    EXPECT_FALSE(touch.intersect(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)}));
    EXPECT_FALSE(touch.occluded(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)}));
    EXPECT_TRUE(touch.spans(Ray{Point3(-5, 0, 0), Vector3(1, 0, 0)}).empty());
    // Even the ray tangent to both at the contact point: each sphere gives a zero-length span.
    const Ray tangent_to_both{Point3(1, 0, -5), Vector3(0, 0, 1)};
    ASSERT_EQ(a->spans(tangent_to_both).size(), 1u);
    EXPECT_FALSE(touch.intersect(tangent_to_both));
}

TEST(BooleanCoincident, TangentRaysMakeNoPhantomHitsInsideTheMaterial) {
    // The ray y = 1 touches the unit sphere at (0, 1, 0), the centre of a second sphere.
    const auto touched = sphere(Point3(0, 0, 0), 1);
    const auto around = sphere(Point3(0, 1, 0), 0.5);
    const Ray from_inside{Point3(-0.3, 1, 0), Vector3(1, 0, 0)};
    ASSERT_EQ(touched->spans(from_inside).size(), 1u);  // the exact tangent: a zero-length span
    for (const auto& node : {boolean(kUnion, touched, around), boolean(kUnion, around, touched),
                             boolean(kDifference, around, touched)}) {
        const std::optional<Hit> hit = node->intersect(from_inside);
        ASSERT_TRUE(hit) << node->kind();
        EXPECT_EQ(hit->t, 0.8) << node->kind();
        EXPECT_EQ(hit->shape, around.get());
        EXPECT_EQ(node->spans(from_inside).size(), 1u);
    }
    // A tangent outside everything else is a touching point of the union, as of the sphere.
    const Boolean apart(kUnion, touched, sphere(Point3(0, 5, 0), 0.5));
    const Ray grazing{Point3(-5, 1, 0), Vector3(1, 0, 0)};
    ASSERT_TRUE(touched->intersect(grazing));
    const std::optional<Hit> hit = apart.intersect(grazing);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 5.0);
    EXPECT_TRUE(apart.occluded(grazing));
}

TEST(Boolean, PropertiesOfABittenEllipsoid) {
    // A stretched ball with a ball bitten out: signed distances combine by max(f_a, -f_b), whose
    // zero set is the result's surface and whose gradient is the active operand's.
    const Point3 bite_center(1.2, 0.3, 0);
    const auto ellipsoid = std::make_shared<Instance>(sphere(Point3(0, 0, 0), 1),
                                                      Transform::scale(Vector3(1.5, 1, 0.8)));
    const Boolean bitten(kDifference, ellipsoid, sphere(bite_center, 0.6));
    const Vector3 axes(1.5, 1, 0.8);
    auto ellipsoid_value = [&](const Point3& p) { return p.cwiseQuotient(axes).squaredNorm() - 1; };
    auto bite_value = [&](const Point3& p) { return (p - bite_center).squaredNorm() - 0.36; };
    const test::SurfaceDescription surface{
        [&](const Point3& p) { return std::max(ellipsoid_value(p), -bite_value(p)); },
        [&](const Point3& p) -> Vector3 {
            if (ellipsoid_value(p) >= -bite_value(p))
                return 2.0 * p.cwiseQuotient(axes).cwiseQuotient(axes);
            return -2.0 * (p - bite_center);
        },
        1.0, bitten.bounds()};
    // max() picks the operand whose surface the point is on; both are zero only on the rim.
    const test::PropertyCounts counts = test::check_shape_properties(bitten, surface, 100000, 59);
    EXPECT_GT(counts.hits, 30000);
    EXPECT_GT(counts.span_checks, 100000);
}

}  // namespace
}  // namespace csgrt
