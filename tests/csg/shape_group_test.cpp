#include "csgrt/csg/shape_group.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "csgrt/accel/factory.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/plane.h"
#include "csgrt/core/sphere.h"
#include "csgrt/csg/compound.h"
#include "support/random.h"
#include "support/scene_parts.h"

namespace csgrt {
namespace {

using Shapes = std::vector<std::shared_ptr<const Shape>>;

// Test fixture: a plane that claims a finite box, so it sits in the structure while giving
// exactly the t of the unbounded plane it forwards to (the same shape answers both).
class BoxedPlane final : public Shape {
public:
    explicit BoxedPlane(std::shared_ptr<const Shape> plane) : plane_(std::move(plane)) {}
    std::string_view kind() const override { return "boxed plane"; }
    Aabb bounds() const override { return Aabb(Point3(-10, -1, -10), Point3(10, 1, 10)); }
    bool is_solid() const override { return false; }
    bool nearest_hit(const Ray& ray, HitRecord& record, QueryScratch& scratch) const override {
        return plane_->nearest_hit(ray, record, scratch);
    }
    bool any_hit(const Ray& ray, QueryScratch& scratch) const override {
        return plane_->any_hit(ray, scratch);
    }
    void find_spans(const Ray&, SpanList& spans, QueryScratch&) const override { spans.clear(); }
    bool contains(const Point3&) const override { return false; }

private:
    std::shared_ptr<const Shape> plane_;
};

// Test fixture: a shape with an empty box, which a group must drop (it can never be hit).
class Nothing final : public Shape {
public:
    std::string_view kind() const override { return "nothing"; }
    Aabb bounds() const override { return Aabb(); }
    bool is_solid() const override { return false; }
    bool nearest_hit(const Ray&, HitRecord&, QueryScratch&) const override {
        ADD_FAILURE() << "a member with an empty box was asked";
        return false;
    }
    bool any_hit(const Ray&, QueryScratch&) const override {
        ADD_FAILURE() << "a member with an empty box was asked";
        return false;
    }
    void find_spans(const Ray&, SpanList& spans, QueryScratch&) const override { spans.clear(); }
    bool contains(const Point3&) const override { return false; }
};

// The exact repeats among mixed_members' spheres (i = 3, 10, 17, 24), which a group drops.
constexpr std::size_t kMixedRepeats = 4;

// Random spheres (some overlapping, some repeated as the same shape, so that ties at equal t
// occur) between two unbounded planes and an empty member.
Shapes mixed_members(std::uint64_t seed) {
    test::Random random(seed);
    Shapes members;
    members.push_back(test::ground_plane(-3.0));
    members.push_back(std::make_shared<Nothing>());
    for (int i = 0; i < 30; ++i) {
        const Point3 centre = random.in_box(Aabb(Point3(-4, -2, -4), Point3(4, 2, 4)));
        members.push_back(std::make_shared<Sphere>(centre, random.uniform(0.2, 1.0)));
        if (i % 7 == 3) members.push_back(members.back());
    }
    members.push_back(test::ground_plane(3.5));
    return members;
}

// The independent answer: every member asked in index order, the nearest kept, a tie at equal
// t going to the lower index.
bool nearest_by_loop(const Shapes& members, const Ray& ray, HitRecord& best) {
    QueryScratch scratch;
    bool found = false;
    for (std::size_t i = 0; i < members.size(); ++i) {
        if (members[i]->bounds().is_empty()) continue;
        HitRecord candidate;
        if (!members[i]->nearest_hit(ray, candidate, scratch)) continue;
        if (found && !(candidate.t < best.t)) continue;
        best = candidate;
        best.object = static_cast<std::uint32_t>(i);
        found = true;
    }
    return found;
}

// Checks the group's nearest and any for `ray` (the k-th ray) against the loop's: the same
// shapes asked the same ray, so identical to the bit. `loop_hit` receives the loop's nearest
// hit. A hit/miss disagreement is fatal: call under ASSERT_NO_FATAL_FAILURE.
void expect_group_agrees_with_loop(const ShapeGroup& group, const Shapes& members, const Ray& ray,
                                   int k, QueryScratch& scratch,
                                   std::optional<HitRecord>& loop_hit) {
    HitRecord expected, actual;
    const bool found = nearest_by_loop(members, ray, expected);
    loop_hit.reset();
    ASSERT_EQ(group.nearest(ray, actual, scratch), found) << k;
    EXPECT_EQ(group.any(ray, scratch), found) << k;
    if (!found) return;
    loop_hit = expected;
    EXPECT_EQ(actual.t, expected.t) << k;
    EXPECT_EQ(actual.object, expected.object) << k;
}

TEST(ShapeGroup, SplitsMembersIntoBoundedAndUnboundedAndDropsEmptyOnes) {
    const Shapes members = mixed_members(1);
    const ShapeGroup group(members, "auto", {});
    ASSERT_EQ(group.unbounded().size(), 2u);
    EXPECT_EQ(group.unbounded()[0], 0u);
    EXPECT_EQ(group.unbounded()[1], members.size() - 1);
    EXPECT_EQ(group.bounded().size(), members.size() - 3 - kMixedRepeats);
    Aabb bounds;
    for (std::size_t i = 0; i < group.bounded().size(); ++i) {
        EXPECT_EQ(&group.bounded().shape(i), members[group.member_of(i)].get());
        bounds.extend(members[group.member_of(i)]->bounds());
    }
    EXPECT_EQ(group.bounded_bounds().lower, bounds.lower);
    EXPECT_EQ(group.bounded_bounds().upper, bounds.upper);
}

TEST(ShapeGroup, EveryStructureGivesTheLoopsNearestAnyAndAllHits) {
    const Shapes members = mixed_members(2);
    test::Random random(3);
    for (const std::string_view name : accelerator_names()) {
        SCOPED_TRACE(std::string(name));
        const ShapeGroup group(members, name, {});
        EXPECT_EQ(group.accelerator_name(), name);
        QueryScratch scratch;
        int hits = 0;
        for (int k = 0; k < 400; ++k) {
            const Point3 origin = random.in_box(Aabb(Point3(-6, -5, -6), Point3(6, 5, 6)));
            const Ray ray{origin, random.unit_vector()};
            std::optional<HitRecord> expected;
            ASSERT_NO_FATAL_FAILURE(
                expect_group_agrees_with_loop(group, members, ray, k, scratch, expected));
            TraversalCounters counters;
            HitRecord counted;
            ASSERT_EQ(group.nearest_counted(ray, counted, scratch, counters), expected.has_value())
                << k;
            if (expected) {
                ++hits;
                EXPECT_EQ(counted.t, expected->t) << k;
                EXPECT_EQ(counted.object, expected->object) << k;
                EXPECT_GE(counters.primitives_tested, group.unbounded().size()) << k;
            }
            std::vector<HitRecord> all;
            group.all(ray, all, scratch);
            std::vector<std::uint32_t> hit_members;
            for (const HitRecord& hit : all) hit_members.push_back(hit.object);
            std::sort(hit_members.begin(), hit_members.end());
            std::vector<std::uint32_t> expected_members;
            for (std::size_t i = 0; i < members.size(); ++i) {
                HitRecord record;
                // An exact repeat (mixed_members repeats the sphere just before) gives none.
                const bool repeat = i > 0 && members[i] == members[i - 1];
                if (!repeat && !members[i]->bounds().is_empty() &&
                    members[i]->nearest_hit(ray, record, scratch))
                    expected_members.push_back(static_cast<std::uint32_t>(i));
            }
            EXPECT_EQ(hit_members, expected_members) << k;
        }
        EXPECT_GT(hits, 200);
    }
}

TEST(ShapeGroup, ATieBetweenABoundedAndAnUnboundedMemberGoesToTheLowerIndex) {
    const auto plane = test::ground_plane(0.0);
    const auto boxed = std::make_shared<BoxedPlane>(plane);
    const Ray down{Point3(0.25, 5, -0.5), Vector3(0.1, -1, 0.2)};
    QueryScratch scratch;
    for (const std::string_view name : accelerator_names()) {
        SCOPED_TRACE(std::string(name));
        const ShapeGroup plane_first(Shapes{plane, boxed}, name, {});
        ASSERT_EQ(plane_first.unbounded().size(), 1u);
        HitRecord record;
        ASSERT_TRUE(plane_first.nearest(down, record, scratch));
        EXPECT_EQ(record.object, 0u);
        const ShapeGroup boxed_first(Shapes{boxed, plane}, name, {});
        ASSERT_TRUE(boxed_first.nearest(down, record, scratch));
        EXPECT_EQ(record.object, 0u);
        // And a sphere that the plane cuts, listed between them, at exactly the plane's t:
        // the same shape twice, so the tie is exact.
        const auto ball = std::make_shared<Sphere>(Point3(0, 0, 0), 2.0);
        const ShapeGroup twice(Shapes{plane, ball, ball}, name, {});
        const Ray sideways{Point3(-5, 0.5, 0), Vector3(1, 0, 0)};
        ASSERT_TRUE(twice.nearest(sideways, record, scratch));
        EXPECT_EQ(record.object, 1u);
    }
}

TEST(ShapeGroup, SaysWhyItChoseItsStructure) {
    const Shapes members = mixed_members(4);
    std::string reason;
    const std::string chosen = choose_accelerator(members.size() - 3 - kMixedRepeats, reason);
    const ShapeGroup automatic(members, "auto", {});
    EXPECT_EQ(automatic.accelerator_name(), chosen);
    EXPECT_EQ(automatic.accelerator_reason(), reason);
    const ShapeGroup requested(members, "grid", {}, "asked for");
    EXPECT_EQ(requested.accelerator_reason(), "asked for");
    EXPECT_EQ(requested.accelerator_stats().primitives, members.size() - 3 - kMixedRepeats);
}

TEST(ShapeGroup, ExactRepeatsAreDroppedAndTheNearestHitIsTheLoops) {
    // The same sphere bare three times, under separately built but equal transforms (one with
    // -0 where the other has +0), and under a transform one ulp away, which is another place.
    const auto ball = std::make_shared<Sphere>(Point3(0.5, 0, 0), 1.0);
    const Transform moved = Transform::translate(Vector3(0.25, 0.0, 0.0));
    const Transform moved_negative_zero = Transform::translate(Vector3(0.25, -0.0, 0.0));
    const Transform nudged = Transform::translate(Vector3(std::nextafter(0.25, 1.0), 0.0, 0.0));
    const Shapes members{ball,
                         std::make_shared<Instance>(ball, moved),
                         ball,
                         std::make_shared<Instance>(ball, moved_negative_zero),
                         std::make_shared<Instance>(ball, nudged),
                         ball};
    std::vector<const Shape*> pointers;
    for (const auto& member : members) pointers.push_back(member.get());
    EXPECT_EQ(exact_repeats(pointers), (std::vector<bool>{false, false, true, true, false, true}));
    test::Random random(11);
    for (const std::string_view name : accelerator_names()) {
        SCOPED_TRACE(std::string(name));
        const ShapeGroup group(members, name, {});
        ASSERT_EQ(group.bounded().size(), 3u);
        EXPECT_EQ(group.member_of(0), 0u);
        EXPECT_EQ(group.member_of(1), 1u);
        EXPECT_EQ(group.member_of(2), 4u);
        QueryScratch scratch;
        for (int k = 0; k < 200; ++k) {
            const Point3 origin = random.in_box(Aabb(Point3(-4, -4, -4), Point3(4, 4, 4)));
            std::optional<HitRecord> expected;
            ASSERT_NO_FATAL_FAILURE(expect_group_agrees_with_loop(
                group, members, Ray{origin, random.unit_vector()}, k, scratch, expected));
        }
    }
    // 4096 coincident copies, each its own Instance, cost one primitive test a ray.
    Shapes pile;
    for (int i = 0; i < 4096; ++i) pile.push_back(std::make_shared<Instance>(ball, moved));
    const ShapeGroup piled(pile, "brute", {});
    QueryScratch scratch;
    HitRecord record;
    TraversalCounters counters;
    ASSERT_TRUE(piled.nearest_counted(Ray{Point3(0.75, 0, -5), Vector3(0, 0, 1)}, record, scratch,
                                      counters));
    EXPECT_EQ(record.object, 0u);
    EXPECT_EQ(counters.primitives_tested, 1u);
}

TEST(ShapeGroup, RejectsANullMemberAndAnUnknownStructure) {
    EXPECT_THROW(ShapeGroup(Shapes{test::ground_plane(0), nullptr}, "auto", {}), InvalidParameter);
    EXPECT_THROW(ShapeGroup(Shapes{test::ground_plane(0)}, "octree", {}), InvalidParameter);
}

}  // namespace
}  // namespace csgrt
