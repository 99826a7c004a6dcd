#pragma once

// The registry of example shapes: for shapes what accelerator_names() is for structures. Every
// shape and part object of core/ as a kind that can be built at any size near any centre
// together with its long double model (reference_shapes.h); instances under rotation,
// non-uniform scale and shear; ready-made compounds; booleans. The stress suites iterate it
// (invalid rays, degenerate sizes, accuracy against long double, every shape under every
// structure), so a shape added here is tested by all of them.
//
// Adding a shape: one example_kinds() entry (its constructor and its reference model).

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "csgrt/core/shapes.h"
#include "csgrt/csg/boolean.h"
#include "csgrt/csg/compound.h"
#include "csgrt/csg/ready_made.h"
#include "stress/reference_judge.h"
#include "stress/reference_shapes.h"
#include "support/random.h"

namespace csgrt::test {

using ShapePointer = std::shared_ptr<const Shape>;
using ReferencePointer = std::shared_ptr<const ReferenceShape>;

/// A kind of shape, built at a size near a centre by its own parameters. `placed` receives the
/// centre it really has (shapes of revolution sit on their axis).
struct ExampleKind {
    std::string name;
    std::function<std::pair<ShapePointer, ReferencePointer>(const Point3& center, double size,
                                                            Point3& placed)>
        make;
};

inline std::vector<ExampleKind> example_kinds() {
    std::vector<ExampleKind> list;
    list.push_back({"plane", [](const Point3& c, double s, Point3& placed) {
                        placed = c;
                        const Normal3 normal(1, 2, 3);
                        (void)s;
                        return std::make_pair(ShapePointer(std::make_shared<Plane>(c, normal)),
                                              ReferencePointer(reference_plane(c, normal)));
                    }});
    // A solid whose hits are the plane's: the same reference, every suite's solid checks too.
    list.push_back({"half_space", [](const Point3& c, double s, Point3& placed) {
                        placed = c;
                        const Normal3 normal(-2, 1, 0.5);
                        (void)s;
                        return std::make_pair(ShapePointer(std::make_shared<HalfSpace>(c, normal)),
                                              ReferencePointer(reference_plane(c, normal)));
                    }});
    list.push_back({"triangle", [](const Point3& c, double s, Point3& placed) {
                        placed = c;
                        const Point3 a = c + s * Vector3(-1, -0.5, 0.2);
                        const Point3 b = c + s * Vector3(1, -0.3, -0.1);
                        const Point3 d = c + s * Vector3(0.1, 1, 0.3);
                        return std::make_pair(ShapePointer(std::make_shared<Triangle>(a, b, d)),
                                              ReferencePointer(reference_triangle(a, b, d)));
                    }});
    list.push_back({"disk", [](const Point3& c, double s, Point3& placed) {
                        placed = c;
                        const Normal3 normal(-1, 2, 0.5);
                        return std::make_pair(ShapePointer(std::make_shared<Disk>(c, normal, s)),
                                              ReferencePointer(reference_disk(c, normal, s)));
                    }});
    list.push_back({"rectangle", [](const Point3& c, double s, Point3& placed) {
                        placed = c;
                        const Point3 corner = c - s * Vector3(0.5, 0.2, 0.3);
                        const Vector3 a = s * Vector3(1, 0.2, -0.1);
                        const Vector3 b = s * Vector3(-0.3, 0.8, 0.4);
                        return std::make_pair(
                            ShapePointer(std::make_shared<Rectangle>(corner, a, b)),
                            ReferencePointer(reference_rectangle(corner, a, b)));
                    }});
    list.push_back(
        {"annulus", [](const Point3& c, double s, Point3& placed) {
             placed = c;
             // The azimuth range [4, 8.5] runs across the seam 0 = 2 pi.
             auto annulus =
                 std::make_shared<Annulus>(c, Normal3(0.3, -1, 0.2), 0.4 * s, s, 4.0, 8.5);
             const SurfaceFrame& frame = annulus->frame();
             return std::make_pair(ShapePointer(annulus), ReferencePointer(reference_annulus(
                                                              c, frame.normal, frame.x_axis,
                                                              frame.z_axis, 0.4 * s, s, 4.0, 8.5)));
         }});
    list.push_back({"box", [](const Point3& c, double s, Point3& placed) {
                        placed = c;
                        const Vector3 half = s * Vector3(1, 0.5, 0.75);
                        return std::make_pair(
                            ShapePointer(std::make_shared<Box>(c - half, c + half)),
                            ReferencePointer(reference_box(c - half, c + half)));
                    }});
    list.push_back({"sphere", [](const Point3& c, double s, Point3& placed) {
                        placed = c;
                        return std::make_pair(ShapePointer(std::make_shared<Sphere>(c, s)),
                                              ReferencePointer(reference_sphere(c, s)));
                    }});
    list.push_back(
        {"part_sphere", [](const Point3& c, double s, Point3& placed) {
             placed = c;
             return std::make_pair(
                 ShapePointer(std::make_shared<PartSphere>(c, s, 4.0, 8.0, 0.6, 2.2)),
                 ReferencePointer(reference_part_sphere(c, s, 4.0, 8.0, 0.6, 2.2)));
         }});
    for (const bool capped : {false, true}) {
        list.push_back(
            {capped ? "cylinder (capped)" : "cylinder (open)",
             [capped](const Point3& c, double s, Point3& placed) {
                 placed = Point3(0, c.y(), 0);
                 return std::make_pair(
                     ShapePointer(std::make_shared<Cylinder>(s, c.y() - s, c.y() + s, capped)),
                     ReferencePointer(reference_cylinder(s, c.y() - s, c.y() + s, capped)));
             }});
    }
    list.push_back({"cone (open frustum)", [](const Point3&, double s, Point3& placed) {
                        placed = Point3(0, s, 0);
                        return std::make_pair(
                            ShapePointer(std::make_shared<Cone>(s, 0.4 * s, 2 * s, false)),
                            ReferencePointer(reference_cone(s, 0.4 * s, 2 * s, false)));
                    }});
    list.push_back({"cone (capped, pointed)", [](const Point3&, double s, Point3& placed) {
                        placed = Point3(0, s, 0);
                        return std::make_pair(
                            ShapePointer(std::make_shared<Cone>(s, 0.0, 2 * s, true)),
                            ReferencePointer(reference_cone(s, 0.0, 2 * s, true)));
                    }});
    list.push_back({"part_cylinder", [](const Point3& c, double s, Point3& placed) {
                        placed = Point3(0, c.y(), 0);
                        return std::make_pair(ShapePointer(std::make_shared<PartCylinder>(
                                                  s, c.y() - s, c.y() + s, 4.5, 8.0)),
                                              ReferencePointer(reference_part_cylinder(
                                                  s, c.y() - s, c.y() + s, 4.5, 8.0)));
                    }});
    for (const double ratio : {0.25, 1e-2, 1e-3}) {
        char name[32];
        std::snprintf(name, sizeof name, "torus r/R=%g", ratio);
        list.push_back({name, [ratio](const Point3&, double s, Point3& placed) {
                            placed = Point3(0, 0, 0);
                            return std::make_pair(
                                ShapePointer(std::make_shared<Torus>(s, ratio * s)),
                                ReferencePointer(reference_torus(s, ratio * s)));
                        }});
    }
    list.push_back(
        {"part_torus", [](const Point3&, double s, Point3& placed) {
             placed = Point3(0, 0, 0);
             return std::make_pair(
                 ShapePointer(std::make_shared<PartTorus>(s, 0.25 * s, 5.0, 9.0, 4.2, 7.7)),
                 ReferencePointer(reference_part_torus(s, 0.25 * s, 5.0, 9.0, 4.2, 7.7)));
         }});
    return list;
}


/// One example: a shape placed in the world, its long double model where one is known (null
/// for booleans, whose reference would need point membership), and the box rays aim into.
struct ExampleShape {
    std::string name;
    ShapePointer shape;
    JudgedShape judged;
    Aabb target;
};

/// The smallest singular value of a linear map: how much it shrinks a length at the most, the
/// conservative factor from world to object distances.
inline double smallest_stretch(const Eigen::Matrix3d& linear) {
    return Eigen::JacobiSVD<Eigen::Matrix3d>(linear).singularValues().minCoeff();
}

/// The box rays aim into: the shape's bounds grown by 5 %, or a cube of `size` around
/// `center` for an unbounded shape.
inline Aabb example_target(const Shape& shape, const Point3& center, double size) {
    const Aabb bounds = shape.bounds();
    if (!bounds.is_finite()) {
        return Aabb(center - Vector3::Constant(size), center + Vector3::Constant(size));
    }
    return enlarged(bounds, 0.05);
}

/// `kind` built at unit size and seen through `world_from_object`, with the reference mapped
/// the same way.
inline ExampleShape instance_example(const ExampleKind& kind, const std::string& how,
                                     const Transform& world_from_object) {
    Point3 unit_center;
    auto [unit_shape, unit_reference] = kind.make(Point3(0, 0, 0), 1.0, unit_center);
    ExampleShape example;
    example.name = kind.name + " (" + how + ")";
    example.shape = std::make_shared<Instance>(unit_shape, world_from_object);
    example.judged.reference = std::make_shared<TransformedShape>(
        unit_reference, world_from_object.linear(), world_from_object.translation());
    example.judged.center = world_from_object.apply_point(unit_center);
    example.judged.size = world_from_object.linear().norm();
    example.judged.object_scale = smallest_stretch(world_from_object.linear());
    example.judged.conditioning =
        Eigen::JacobiSVD<Eigen::Matrix3d>(world_from_object.linear()).singularValues()(0) /
        example.judged.object_scale;
    example.target = example_target(*example.shape, example.judged.center, example.judged.size);
    return example;
}

/// A solid of revolution about y (height `axis.norm()`) in long double, turned onto the axis
/// from `base` along `axis` (any such turn gives the same solid).
inline ReferencePointer turned_onto(ReferencePointer about_y, const Point3& base,
                                    const Vector3& axis) {
    const Eigen::Matrix3d turn =
        Eigen::Quaterniond::FromTwoVectors(Vector3(0, 1, 0), axis).toRotationMatrix();
    return std::make_shared<TransformedShape>(std::move(about_y), turn, base);
}

/// Every example: each kind at unit size by its own parameters; instances with rotation,
/// non-uniform scale and shear (each kind under all three at once, and three kinds under one
/// each); the ready-made compounds; a compound of shapes; booleans.
inline std::vector<ExampleShape> example_shapes() {
    std::vector<ExampleShape> list;
    const std::vector<ExampleKind> kinds = example_kinds();
    const Point3 center(0.25, -0.5, 0.125);
    for (const ExampleKind& kind : kinds) {
        ExampleShape own;
        own.name = kind.name;
        std::tie(own.shape, own.judged.reference) = kind.make(center, 1.0, own.judged.center);
        own.target = example_target(*own.shape, own.judged.center, 1.0);
        list.push_back(own);
    }
    const Transform rotation =
        Transform::translate(Vector3(0.5, 0.25, -0.75)) * Transform::rotate(Vector3(1, 2, 3), 0.7);
    const Transform stretch = Transform::scale(Vector3(2.0, 1.0, 0.5));
    const Transform shear = Transform::shear(0, 1, 0.6);
    for (const ExampleKind& kind : kinds) {
        list.push_back(
            instance_example(kind, "rotated, stretched, sheared", rotation * stretch * shear));
    }
    auto find = [&](const std::string& name) -> const ExampleKind& {
        for (const ExampleKind& kind : kinds) {
            if (kind.name == name) return kind;
        }
        std::abort();
    };
    list.push_back(instance_example(find("cylinder (capped)"), "rotated", rotation));
    list.push_back(instance_example(find("torus r/R=0.25"), "non-uniform scale", stretch));
    list.push_back(instance_example(find("box"), "sheared", shear));

    // Ready-made compounds. The solid cylinder and cone have references from their documented
    // geometry; the boolean ones (ring, bowl, rounded box) have none.
    auto solid_of_revolution = [&](std::string name, ShapePointer shape, const Point3& base,
                                   const Point3& top, ReferencePointer about_y) {
        ExampleShape solid;
        solid.name = std::move(name);
        solid.shape = std::move(shape);
        solid.judged.reference = turned_onto(std::move(about_y), base, top - base);
        solid.judged.center = 0.5 * (base + top);
        solid.target = example_target(*solid.shape, solid.judged.center, 1.0);
        list.push_back(solid);
    };
    const Point3 base(0.2, -0.7, 0.1), top(-0.3, 0.9, 0.4);
    solid_of_revolution("ready-made solid cylinder", make_solid_cylinder(base, top, 0.45), base,
                        top, reference_cylinder(0.45, 0.0, (top - base).norm(), true));
    solid_of_revolution("ready-made solid cone", make_solid_cone(base, top, 0.6, 0.1), base, top,
                        reference_cone(0.6, 0.1, (top - base).norm(), true));
    auto without_reference = [&](std::string name, ShapePointer shape) {
        ExampleShape example;
        example.name = std::move(name);
        example.shape = std::move(shape);
        example.target = example_target(*example.shape, Point3(0, 0, 0), 1.0);
        list.push_back(example);
    };
    without_reference("ready-made thick ring", make_thick_ring(-0.4, 0.4, 0.5, 1.0));
    without_reference("ready-made bowl", make_bowl(1.0, 0.8));
    without_reference("ready-made rounded box",
                      make_rounded_box(Point3(-1, -0.6, -0.8), Point3(1, 0.6, 0.8), 0.2));
    auto sphere = std::make_shared<Sphere>(Point3(0, 0, 0), 1.0);
    auto box = std::make_shared<Box>(Point3(-1, -1, -1), Point3(1, 1, 1));
    without_reference("compound of a sphere, a box and a torus",
                      std::make_shared<Compound>(std::vector<ShapePointer>{
                          std::make_shared<Sphere>(Point3(-2, 0, 0), 0.8),
                          std::make_shared<Box>(Point3(0.5, -0.5, -0.5), Point3(1.5, 0.5, 0.5)),
                          std::make_shared<Instance>(std::make_shared<Torus>(0.6, 0.2),
                                                     Transform::translate(Vector3(3, 0, 0)))}));
    without_reference("difference box - sphere",
                      std::make_shared<Boolean>(BooleanOperation::Difference, box, sphere));
    without_reference(
        "union box + shifted sphere",
        std::make_shared<Boolean>(
            BooleanOperation::Union, box,
            std::make_shared<Instance>(sphere, Transform::translate(Vector3(1, 0, 0)))));
    without_reference("intersection sphere * stretched box",
                      std::make_shared<Boolean>(
                          BooleanOperation::Intersection, sphere,
                          std::make_shared<Instance>(box, Transform::scale(Vector3(1.5, 0.5, 2)))));
    return list;
}

}  // namespace csgrt::test
