// Every registered example shape (support/example_shapes.h) that has a long double model, as
// a member of a compound and inside booleans, under every registered structure
// (accelerator_names()), checked ray by ray against the long double reference shapes
// (reference_shapes.h): the structures must not change a single answer outside the
// ambiguity band.
//
// A case is a group of four copies of the shape, the shape itself and three translated
// instances of it, 3 sizes apart along three directions, so that every structure has several
// members to order and cull. Its reference is the union of the copies' references: a compound
// reports the nearest surface of any member. "Inside booleans" puts each solid in two booleans
// whose answer the operands' references give exactly: the union with a sphere that lies apart
// from it (the union's surface is both surfaces) and the intersection with a box that holds it
// with room to spare (the intersection is the solid itself).
//
// The ambiguity band is the one derived in reference_judge.h (kTrimBand point scales / cos at
// trims, kTangentBand point scales at tangencies), with the point scale of the whole group:
// its centre and its extent bound those of each member, and each instance's translation is a
// rounding of |o| + |c| already counted there. A ray is judged once; then every structure must
// agree with the verdict: no hit where the reference has none, a hit where it has one, with t
// within error_bound (kRootUlps point scales along the ray at the crossing's cosine, plus 4
// ulps of t), and occluded equal to intersect.
//
// The second test takes the examples that have no model in the registry (the ready-made
// thick ring, bowl and rounded box, a compound, booleans) and real booleans of every solid
// (each minus a ball that bites into it, and intersected with a box that cuts it), with the
// long double models of reference_booleans.h: the ready-made compounds as the surfaces their
// documentation describes, booleans by combining the operands' crossings.
//
// Heavy (ctest label, by its name): 10^5 rays a case in the release build, an eighth under
// the sanitizers (test::scaled).

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/accel/factory.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/complement.h"
#include "csgrt/csg/compound.h"
#include "stress/reference_booleans.h"
#include "stress/reference_judge.h"
#include "stress/summary.h"
#include "support/answer_tally.h"
#include "support/example_shapes.h"
#include "support/random.h"
#include "support/test_scale.h"

namespace csgrt {
namespace {

using test::ReferencePointer;
using test::ShapePointer;

/// The union of several reference shapes: every crossing of every one.
class UnionReference final : public test::ReferenceShape {
public:
    explicit UnionReference(std::vector<ReferencePointer> members) : members_(std::move(members)) {}
    void crossings(const test::LongRay& ray, test::LineCrossings& out) const override {
        for (const ReferencePointer& member : members_) member->crossings(ray, out);
    }

private:
    std::vector<ReferencePointer> members_;
};

struct GroupCase {
    std::string name;
    std::vector<ShapePointer> members;
    test::JudgedShape judged;
    /// The box around every member (rays from afar start around it) and each member's own
    /// box (rays aim into one of them, in turn).
    Aabb target;
    std::vector<Aabb> member_targets;
};

/// The shape and three translated copies of it, with the union of their references.
GroupCase group_of(const std::string& name, const ShapePointer& shape,
                   const ReferencePointer& reference, const test::JudgedShape& judged,
                   const Aabb& target) {
    GroupCase group;
    group.name = name;
    const double extent = (target.upper - target.lower).maxCoeff();
    const Vector3 offsets[] = {Vector3(0, 0, 0), 3 * extent * Vector3(1, 0.2, 0),
                               3 * extent * Vector3(-0.3, 1, 0.1),
                               3 * extent * Vector3(0.2, -0.1, 1)};
    std::vector<ReferencePointer> references;
    Aabb whole;
    for (const Vector3& offset : offsets) {
        const bool moved = offset.squaredNorm() > 0.0;
        group.members.push_back(
            moved ? std::make_shared<Instance>(shape, Transform::translate(offset)) : shape);
        references.push_back(moved ? std::make_shared<test::TransformedShape>(
                                         reference, Eigen::Matrix3d::Identity(), offset)
                                   : reference);
        group.member_targets.push_back(Aabb(target.lower + offset, target.upper + offset));
        whole.extend(group.member_targets.back());
    }
    group.judged.reference = std::make_shared<UnionReference>(std::move(references));
    group.judged.center = whole.center();
    group.judged.size = std::max(judged.size, (whole.upper - whole.lower).norm());
    group.judged.object_scale = judged.object_scale;
    group.judged.conditioning = judged.conditioning;
    group.target = whole;
    return group;
}

std::vector<GroupCase> all_cases() {
    std::vector<GroupCase> cases;
    for (const test::ExampleShape& example : test::example_shapes()) {
        if (!example.judged.reference) continue;
        cases.push_back(group_of(example.name, example.shape, example.judged.reference,
                                 example.judged, example.target));
        // Booleans of the solids placed by their own parameters (their instances are covered
        // as compound members above).
        // (An unbounded solid, a half-space, would hold the sphere and cross the holder box,
        // whose surfaces the references below leave out.)
        if (!example.shape->is_solid() || example.shape->kind() == "instance" ||
            !example.shape->bounds().is_finite())
            continue;
        // The union with a sphere 2 extents beyond the solid's box, the intersection with a box
        // holding the solid's box with half an extent to spare.
        const Aabb& box = example.target;
        const double extent = (box.upper - box.lower).maxCoeff();
        const Point3 apart = box.upper + Vector3::Constant(2 * extent);
        auto sphere = std::make_shared<Sphere>(apart, 0.5 * extent);
        test::JudgedShape with_sphere = example.judged;
        with_sphere.reference = std::make_shared<UnionReference>(std::vector<ReferencePointer>{
            example.judged.reference, test::reference_sphere(apart, 0.5 * extent)});
        Aabb union_target = box;
        union_target.extend(sphere->bounds());
        cases.push_back(
            group_of(example.name + " in a union",
                     std::make_shared<Boolean>(BooleanOperation::Union, example.shape, sphere),
                     with_sphere.reference, with_sphere, union_target));
        const Vector3 spare = Vector3::Constant(0.5 * extent);
        auto holder = std::make_shared<Box>(box.lower - spare, box.upper + spare);
        cases.push_back(group_of(
            example.name + " in an intersection",
            std::make_shared<Boolean>(BooleanOperation::Intersection, example.shape, holder),
            example.judged.reference, example.judged, box));
    }
    return cases;
}

/// `rays` rays at the group `c` under every registered structure, each judged once against the
/// reference; prints the case's row and returns its tally.
test::AnswerTally check_case(const GroupCase& c, int rays, std::uint64_t seed,
                             bool must_agree = true) {
    const auto names = accelerator_names();
    std::vector<std::shared_ptr<const Compound>> structures;
    for (const std::string_view name : names) {
        CompoundConfig config;
        config.accelerator = std::string(name);
        structures.push_back(std::make_shared<Compound>(c.members, config));
    }
    test::Random random(seed);
    test::AnswerTally tally;
    const double size = (c.target.upper - c.target.lower).norm();
    for (int i = 0; i < rays; ++i) {
        Ray ray;
        const Aabb& aim = c.member_targets[(i / 4) % c.member_targets.size()];
        if (i % 4 == 3) {
            // Along a world axis, so direction components are exactly zero.
            const int axis = i % 3;
            ray.origin = random.in_box(aim);
            ray.direction = Vector3::Zero();
            ray.direction[axis] = random.uniform() < 0.5 ? -1.0 : 1.0;
            ray.origin[axis] -= 2.0 * size * ray.direction[axis];
        } else {
            const double distance = i % 4 == 0 ? 0.3 : (i % 4 == 1 ? 2.0 : 20.0);
            ray.origin = c.target.center() + distance * size * random.unit_vector();
            Vector3 direction = random.in_box(aim) - ray.origin;
            if (direction.squaredNorm() == 0.0) direction = random.unit_vector();
            ray.direction = direction.normalized() * random.uniform(0.25, 4.0);
        }
        ++tally.rays;
        const test::Verdict verdict = test::judge(c.judged, ray);
        if (verdict.ambiguous) {
            ++tally.ambiguous;
            continue;
        }
        if (verdict.hit) ++tally.reference_hits;
        for (std::size_t s = 0; s < structures.size(); ++s) {
            const std::optional<Hit> hit = structures[s]->intersect(ray);
            // The count this structure's answer adds to if it disagrees: intersect's or
            // occluded's hit/miss, else intersect's t.
            long* disagreement = nullptr;
            if (hit.has_value() != verdict.hit || structures[s]->occluded(ray) != verdict.hit) {
                disagreement = verdict.hit ? &tally.false_misses : &tally.false_hits;
            } else if (hit) {
                const double t = static_cast<double>(verdict.t);
                const double error = std::abs(hit->t - t);
                const double bound =
                    test::error_bound(c.judged, ray, t, static_cast<double>(verdict.cosine));
                tally.max_ratio = std::max(tally.max_ratio, error / bound);
                if (t > 0.0)
                    tally.max_relative_error = std::max(tally.max_relative_error, error / t);
                if (error > bound) disagreement = &tally.wrong_t;
            }
            if (disagreement) {
                ++*disagreement;
                if (tally.disagreements() <= 5 && must_agree) {
                    ADD_FAILURE() << c.name << " under " << names[s] << ": hit "
                                  << (hit ? hit->t : -1.0) << ", reference "
                                  << (verdict.hit ? static_cast<double>(verdict.t) : -1.0)
                                  << " for Ray{Point3(" << ray.origin.x() << ", " << ray.origin.y()
                                  << ", " << ray.origin.z() << "), Vector3(" << ray.direction.x()
                                  << ", " << ray.direction.y() << ", " << ray.direction.z() << ")}";
                }
            }
        }
    }
    std::printf("  | %s | %zu | %ld | %ld | %ld | %ld | %.1e | %.3f |\n", c.name.c_str(),
                structures.size(), tally.rays, tally.ambiguous, tally.reference_hits,
                tally.disagreements(), tally.max_relative_error, tally.max_ratio);
    if (!must_agree) return tally;
    EXPECT_EQ(tally.disagreements(), 0) << c.name;
    // The check must bite: most rays are judged, and at least a thousandth hit (the thin
    // tori under shear are hit by 0.16 % of the rays aimed at their boxes).
    EXPECT_LT(tally.ambiguous, tally.rays / 10) << c.name;
    EXPECT_GT(tally.reference_hits, tally.rays / 1000) << c.name;
    test::summarize(c.name + " under every structure", tally.rays, tally.disagreements(),
                    tally.max_relative_error, "rel t");
    return tally;
}

void print_header() {
    std::printf(
        "\n  | case | structures | rays | ambiguous | reference hits | disagreements"
        " | max rel t error | worst error / bound |\n");
}

void print_total(const test::AnswerTally& total, std::size_t cases) {
    std::printf("  | all (%zu cases) | %zu | %ld | %ld | %ld | %ld | %.1e | %.3f |\n\n", cases,
                accelerator_names().size(), total.rays, total.ambiguous, total.reference_hits,
                total.disagreements(), total.max_relative_error, total.max_ratio);
}

TEST(StructureShapesReferenceHeavy, EveryShapeUnderEveryStructureAgainstLongDouble) {
    const int rays = test::scaled(100000, 2000);
    const std::vector<GroupCase> cases = all_cases();
    print_header();
    test::AnswerTally total;
    std::uint64_t seed = 16000;
    for (const GroupCase& c : cases) total.add(check_case(c, rays, ++seed));
    print_total(total, cases.size());
}

/// The long double models of the examples the registry has none for, by name, from their
/// documented geometry (csg/ready_made.h and the registry's own description of each).
std::map<std::string, test::JudgedShape> models_of_the_rest() {
    using test::ReferenceOperation;
    std::map<std::string, test::JudgedShape> models;
    auto model = [&](const std::string& name, ReferencePointer reference) {
        models[name].reference = std::move(reference);
    };
    model("ready-made thick ring", test::reference_thick_ring(-0.4, 0.4, 0.5, 1.0));
    model("ready-made bowl", test::reference_bowl(1.0, 0.8));
    model("ready-made rounded box",
          test::reference_rounded_box(Point3(-1, -0.6, -0.8), Point3(1, 0.6, 0.8), 0.2));
    const ReferencePointer unit_sphere = test::reference_sphere(Point3(0, 0, 0), 1.0);
    const ReferencePointer unit_box = test::reference_box(Point3(-1, -1, -1), Point3(1, 1, 1));
    model(
        "compound of a sphere, a box and a torus",
        std::make_shared<UnionReference>(std::vector<ReferencePointer>{
            test::reference_sphere(Point3(-2, 0, 0), 0.8),
            test::reference_box(Point3(0.5, -0.5, -0.5), Point3(1.5, 0.5, 0.5)),
            std::make_shared<test::TransformedShape>(
                test::reference_torus(0.6, 0.2), Eigen::Matrix3d::Identity(), Vector3(3, 0, 0))}));
    model("difference box - sphere",
          test::reference_boolean(ReferenceOperation::kDifference, unit_box, unit_sphere));
    model("union box + shifted sphere",
          test::reference_boolean(ReferenceOperation::kUnion, unit_box,
                                  std::make_shared<test::TransformedShape>(
                                      unit_sphere, Eigen::Matrix3d::Identity(), Vector3(1, 0, 0))));
    const Eigen::Matrix3d stretch = Vector3(1.5, 0.5, 2).asDiagonal();
    model("intersection sphere * stretched box",
          test::reference_boolean(
              ReferenceOperation::kIntersection, unit_sphere,
              std::make_shared<test::TransformedShape>(unit_box, stretch, Vector3::Zero())));
    // The stretched box's trims are in its own units: judged as an instance of that stretch.
    models["intersection sphere * stretched box"].object_scale = 0.5;
    models["intersection sphere * stretched box"].conditioning = 4.0;
    return models;
}

/// Which solids boolean_cases() takes, and whether it cuts them by a box too.
enum class SolidsTaken { kOwnParameters, kPlacedByInstances };

/// Bounded solids with a model, as an operand of real booleans: minus a ball centred halfway
/// from its box's centre to a corner (radius 0.35 of the box's largest side: the ball bites
/// into every one, the pointed cone's tip included), and, for the solids placed by their own
/// parameters, also intersected with a box that keeps what lies below 0.13 of that side above
/// the centre, and the box and the complement of the ball. The instances under one transform
/// each and the ready-made solids (instances too) take the difference only; the instances
/// under all three transforms at once are compound members in the first test (a boolean of
/// the thinnest sheared torus is hit by too few rays to judge).
std::vector<GroupCase> boolean_cases(SolidsTaken taken) {
    using test::ReferenceOperation;
    std::vector<GroupCase> cases;
    for (const test::ExampleShape& example : test::example_shapes()) {
        if (!example.judged.reference || !example.shape->is_solid() ||
            !example.shape->bounds().is_finite())
            continue;
        const bool own = example.shape->kind() != "instance";
        if (own != (taken == SolidsTaken::kOwnParameters) ||
            example.name.find("(rotated, stretched, sheared)") != std::string::npos)
            continue;
        const Aabb& box = example.target;
        const double extent = (box.upper - box.lower).maxCoeff();
        const Point3 bite_centre = box.center() + 0.5 * (box.upper - box.center());
        const double bite_radius = 0.35 * extent;
        auto bite = std::make_shared<Sphere>(bite_centre, bite_radius);
        test::JudgedShape bitten = example.judged;
        bitten.reference =
            test::reference_boolean(ReferenceOperation::kDifference, example.judged.reference,
                                    test::reference_sphere(bite_centre, bite_radius));
        cases.push_back(
            group_of(example.name + " minus a ball",
                     std::make_shared<Boolean>(BooleanOperation::Difference, example.shape, bite),
                     bitten.reference, bitten, box));
        if (!own) continue;
        const Vector3 spare = Vector3::Constant(0.1 * extent);
        Point3 cut_upper = box.upper + spare;
        cut_upper.y() = box.center().y() + 0.13 * extent;
        auto cutter = std::make_shared<Box>(box.lower - spare, cut_upper);
        test::JudgedShape cut = example.judged;
        cut.reference =
            test::reference_boolean(ReferenceOperation::kIntersection, example.judged.reference,
                                    test::reference_box(box.lower - spare, cut_upper));
        cases.push_back(group_of(
            example.name + " cut by a box",
            std::make_shared<Boolean>(BooleanOperation::Intersection, example.shape, cutter),
            cut.reference, cut, box));
        // The complement (csg/complement.h) as a boolean's operand: the box and not the ball is
        // the box minus the ball.
        if (example.name == "box") {
            cases.push_back(
                group_of("box and not a ball",
                         std::make_shared<Boolean>(BooleanOperation::Intersection, example.shape,
                                                   std::make_shared<Complement>(bite)),
                         bitten.reference, bitten, box));
        }
    }
    return cases;
}

void check_cases(const std::vector<GroupCase>& cases, std::uint64_t seed) {
    const int rays = test::scaled(100000, 2000);
    print_header();
    test::AnswerTally total;
    for (const GroupCase& c : cases) total.add(check_case(c, rays, ++seed));
    print_total(total, cases.size());
}

TEST(StructureShapesReferenceHeavy, ReadyMadeCompoundsAndPlacedBooleansUnderEveryStructure) {
    const std::map<std::string, test::JudgedShape> models = models_of_the_rest();
    std::vector<GroupCase> cases;
    for (const test::ExampleShape& example : test::example_shapes()) {
        if (example.judged.reference) continue;
        const auto found = models.find(example.name);
        if (found == models.end()) {
            ADD_FAILURE() << "no long double model for the example \"" << example.name
                          << "\": add one to models_of_the_rest()";
            continue;
        }
        cases.push_back(group_of(example.name, example.shape, found->second.reference,
                                 found->second, example.target));
    }
    EXPECT_EQ(cases.size(), models.size()) << "a model for an example the registry lost?";
    const std::vector<GroupCase> booleans = boolean_cases(SolidsTaken::kPlacedByInstances);
    cases.insert(cases.end(), booleans.begin(), booleans.end());
    check_cases(cases, 16500);

    // The control: the box minus the ball judged against the model of the box alone must
    // disagree on the rays that reach the bite (the boolean model is what makes the verdicts
    // right there).
    const std::vector<GroupCase> own = boolean_cases(SolidsTaken::kOwnParameters);
    const auto bitten_box = std::find_if(
        own.begin(), own.end(), [](const GroupCase& c) { return c.name == "box minus a ball"; });
    ASSERT_NE(bitten_box, own.end());
    const std::vector<test::ExampleShape> examples = test::example_shapes();
    const auto box = std::find_if(examples.begin(), examples.end(),
                                  [](const test::ExampleShape& e) { return e.name == "box"; });
    ASSERT_NE(box, examples.end());
    const GroupCase wrong =
        group_of("control: box minus a ball judged as the box", bitten_box->members.front(),
                 box->judged.reference, box->judged, box->target);
    const test::AnswerTally control = check_case(wrong, test::scaled(10000, 2000), 16999, false);
    EXPECT_GT(control.disagreements(), control.rays / 20);
}

TEST(StructureShapesReferenceHeavy, BooleansOfEverySolidUnderEveryStructure) {
    check_cases(boolean_cases(SolidsTaken::kOwnParameters), 16700);
}

}  // namespace
}  // namespace csgrt
