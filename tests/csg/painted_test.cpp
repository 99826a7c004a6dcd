// Painted shapes: per-operand materials in CSG (csg/painted.h). A hit carries the material of
// the innermost painted shape on its path, through instances, booleans, compounds and span
// lists; everything else about the shape is its child's.
#include "csgrt/csg/painted.h"

#include <gtest/gtest.h>

#include <memory>

#include "csgrt/core/error.h"
#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"

namespace csgrt {
namespace {

Ray along_z(double x, double y) {
    Ray ray;
    ray.origin = Point3(x, y, 10.0);
    ray.direction = Vector3(0.0, 0.0, -1.0);
    return ray;
}

std::shared_ptr<const Shape> painted(std::shared_ptr<const Shape> shape, std::uint32_t material) {
    return std::make_shared<Painted>(std::move(shape), material);
}

TEST(Painted, AnswersAsItsShapeAndGivesItsHitsItsMaterial) {
    const auto sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    const auto red = painted(sphere, 3);
    EXPECT_EQ(red->bounds().lower, sphere->bounds().lower);
    EXPECT_TRUE(red->is_solid());
    EXPECT_TRUE(red->contains(Point3(0.5, 0, 0)));
    EXPECT_FALSE(red->contains(Point3(1.5, 0, 0)));
    EXPECT_TRUE(red->occluded(along_z(0.5, 0)));
    const std::optional<Hit> hit = red->intersect(along_z(0.6, 0.0));
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->material, 3u);
    EXPECT_EQ(hit->t, sphere->intersect(along_z(0.6, 0.0))->t);
    // A bare shape's hits have no material of their own: the scene object's applies.
    EXPECT_EQ(sphere->intersect(along_z(0.6, 0.0))->material, kNoIndex);
    const SpanList spans = red->spans(along_z(0.0, 0.0));
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_EQ(spans[0].enter.material, 3u);
    EXPECT_EQ(spans[0].exit.material, 3u);
}

TEST(Painted, TheInnermostPaintWinsThroughInstancesAndCompounds) {
    const auto inner = painted(std::make_shared<Sphere>(Point3(0, 0, 0), 1.0), 1);
    const auto outer =
        painted(std::make_shared<Instance>(inner, Transform::translate(Vector3(2, 0, 0))), 2);
    EXPECT_EQ(outer->intersect(along_z(2.0, 0.0))->material, 1u);
    // A compound of a painted and an unpainted child, painted as a whole: the painted child
    // keeps its own material, the other takes the compound's.
    const auto group = painted(std::make_shared<Compound>(std::vector<std::shared_ptr<const Shape>>{
                                   inner, std::make_shared<Sphere>(Point3(3, 0, 0), 1.0)}),
                               5);
    EXPECT_EQ(group->intersect(along_z(0.0, 0.0))->material, 1u);
    EXPECT_EQ(group->intersect(along_z(3.0, 0.0))->material, 5u);
}

TEST(Painted, ACsgCutShowsTheSubtractedOperandsMaterial) {
    // A box (material 1) minus a ball at its corner (material 2): the cut surface inside the
    // bite belongs to the ball, so it shows material 2 (with the normal flipped outward of the
    // result); the box's own faces show material 1.
    const auto difference =
        make_difference(painted(std::make_shared<Box>(Point3(0, 0, 0), Point3(1, 1, 1)), 1),
                        {painted(std::make_shared<Sphere>(Point3(1, 1, 1), 0.5), 2)});
    const std::optional<Hit> face = difference->intersect(along_z(0.2, 0.2));
    ASSERT_TRUE(face);
    EXPECT_EQ(face->material, 1u);
    EXPECT_DOUBLE_EQ(face->t, 9.0);
    const std::optional<Hit> cut = difference->intersect(along_z(0.9, 0.9));
    ASSERT_TRUE(cut);
    EXPECT_EQ(cut->material, 2u);
    EXPECT_GT(cut->t, 9.0);                     // below the top face, inside the bite
    EXPECT_GT(cut->geometric_normal.z(), 0.0);  // facing out of the result, up the ray
    // A union's and an intersection's surfaces keep their own operands' materials.
    const auto a = painted(std::make_shared<Sphere>(Point3(-0.5, 0, 0), 0.8), 7);
    const auto b = painted(std::make_shared<Sphere>(Point3(0.5, 0, 0), 0.8), 8);
    const auto both = make_union({a, b});
    EXPECT_EQ(both->intersect(along_z(-1.0, 0.0))->material, 7u);
    EXPECT_EQ(both->intersect(along_z(1.0, 0.0))->material, 8u);
    const auto lens = make_intersection({a, b});
    const SpanList spans = lens->spans(along_z(0.0, 0.0));
    ASSERT_EQ(spans.size(), 1u);
    EXPECT_TRUE(spans[0].enter.material == 7u || spans[0].enter.material == 8u);
}

TEST(Painted, RefusesANullShapeAndMaterialsBeyondTheRecordsField) {
    EXPECT_THROW(Painted(nullptr, 0), InvalidParameter);
    const auto sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    EXPECT_NO_THROW(Painted(sphere, kMaxPaintedMaterial));
    EXPECT_THROW(Painted(sphere, kMaxPaintedMaterial + 1), InvalidParameter);
}

}  // namespace
}  // namespace csgrt
