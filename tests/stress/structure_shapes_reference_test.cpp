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
// Heavy (ctest label, by its name): 10^5 rays a case in the release build, an eighth under
// the sanitizers (test::scaled).

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "csgrt/accel/factory.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "stress/reference_judge.h"
#include "stress/summary.h"
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
        group.members.push_back(moved ? std::make_shared<Instance>(
                                            shape, Transform::translate(offset))
                                      : shape);
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
        cases.push_back(group_of(
            example.name + " in a union",
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

struct Tally {
    long rays = 0;
    long ambiguous = 0;
    long reference_hits = 0;
    long disagreements = 0;
    double max_relative_error = 0.0;  // |t - t_ref| / t_ref over judged hits
    double max_ratio = 0.0;           // error / bound
};

TEST(StructureShapesReferenceHeavy, EveryShapeUnderEveryStructureAgainstLongDouble) {
    const int rays = test::scaled(100000, 2000);
    const std::vector<GroupCase> cases = all_cases();
    const auto names = accelerator_names();
    std::printf(
        "\n  | case | structures | rays | ambiguous | reference hits | disagreements"
        " | max rel t error | worst error / bound |\n");
    Tally total;
    std::uint64_t seed = 16000;
    for (const GroupCase& c : cases) {
        std::vector<std::shared_ptr<const Compound>> structures;
        for (const std::string_view name : names) {
            CompoundConfig config;
            config.accelerator = std::string(name);
            structures.push_back(std::make_shared<Compound>(c.members, config));
        }
        test::Random random(++seed);
        Tally tally;
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
                bool agrees = hit.has_value() == verdict.hit &&
                              structures[s]->occluded(ray) == hit.has_value();
                if (agrees && hit) {
                    const double t = static_cast<double>(verdict.t);
                    const double error = std::abs(hit->t - t);
                    const double bound = test::error_bound(c.judged, ray, t,
                                                           static_cast<double>(verdict.cosine));
                    tally.max_ratio = std::max(tally.max_ratio, error / bound);
                    if (t > 0.0) tally.max_relative_error =
                        std::max(tally.max_relative_error, error / t);
                    agrees = error <= bound;
                }
                if (!agrees) {
                    ++tally.disagreements;
                    ADD_FAILURE() << c.name << " under " << names[s] << ": hit "
                                  << (hit ? hit->t : -1.0) << ", reference "
                                  << (verdict.hit ? static_cast<double>(verdict.t) : -1.0)
                                  << " for Ray{Point3(" << ray.origin.x() << ", "
                                  << ray.origin.y() << ", " << ray.origin.z() << "), Vector3("
                                  << ray.direction.x() << ", " << ray.direction.y() << ", "
                                  << ray.direction.z() << ")}";
                }
            }
        }
        std::printf("  | %s | %zu | %ld | %ld | %ld | %ld | %.1e | %.3f |\n", c.name.c_str(),
                    structures.size(), tally.rays, tally.ambiguous, tally.reference_hits,
                    tally.disagreements, tally.max_relative_error, tally.max_ratio);
        EXPECT_EQ(tally.disagreements, 0) << c.name;
        // The check must bite: most rays are judged, and at least a thousandth hit (the thin
        // tori under shear are hit by 0.16 % of the rays aimed at their boxes).
        EXPECT_LT(tally.ambiguous, tally.rays / 10) << c.name;
        EXPECT_GT(tally.reference_hits, tally.rays / 1000) << c.name;
        test::summarize(c.name + " under every structure", tally.rays, tally.disagreements,
                        tally.max_relative_error, "rel t");
        total.rays += tally.rays;
        total.ambiguous += tally.ambiguous;
        total.reference_hits += tally.reference_hits;
        total.disagreements += tally.disagreements;
        total.max_relative_error = std::max(total.max_relative_error, tally.max_relative_error);
        total.max_ratio = std::max(total.max_ratio, tally.max_ratio);
    }
    std::printf("  | all (%zu cases) | %zu | %ld | %ld | %ld | %ld | %.1e | %.3f |\n\n",
                cases.size(), names.size(), total.rays, total.ambiguous, total.reference_hits,
                total.disagreements, total.max_relative_error, total.max_ratio);
}

}  // namespace
}  // namespace csgrt
