#pragma once

#include <memory>

#include "csgrt/core/shape.h"

namespace csgrt {

// Ready-made compound objects after Suffern, "Ray Tracing from the Ground Up" (2007), ch. 19-21
// and 29. The book assembles them from open surfaces (an open cylinder and two disks make its
// solid cylinder); here each is built from core solids, placed by instances and combined by
// CSG booleans, so every one is itself a solid (spans, contains) and may be a CSG operand. The
// builders return ordinary shapes: nothing here is a new kind of Shape. Every builder throws
// InvalidParameter naming itself and the parameter for parameters it cannot use.

/// The solid cylinder of `radius` whose axis runs from the centre of its `bottom` cap to the
/// centre of its `top` cap (a capped Cylinder placed by an Instance; for an axis along +-x,
/// +-y or +-z the placement is an exact permutation, so faces land exactly on the given
/// coordinates).
std::shared_ptr<const Shape> make_solid_cylinder(const Point3& bottom, const Point3& top,
                                                 double radius);

/// The solid cone or frustum with a disk of `base_radius` around `base` and one of
/// `top_radius` around `top` (0: a pointed cone with its apex at `top`).
std::shared_ptr<const Shape> make_solid_cone(const Point3& base, const Point3& top,
                                             double base_radius, double top_radius = 0.0);

/// The thick ring (annular tube) about the y axis: inner_radius <= sqrt(x^2 + z^2) <=
/// outer_radius, y_min <= y <= y_max. The outer solid cylinder minus an inner one that reaches
/// beyond both ends, so no cap is cut by a coincident surface; the ring's flat ends are the
/// outer cylinder's caps.
std::shared_ptr<const Shape> make_thick_ring(double y_min, double y_max, double inner_radius,
                                             double outer_radius);

/// The bowl: a hemispherical shell around the origin, open upward, inner_radius <= |p| <=
/// outer_radius and y <= 0, with a flat rim in the plane y = 0 (Suffern's flat-rimmed bowl).
/// The ball minus the inner ball, intersected with a solid cylinder below y = 0 whose top cap
/// is the rim.
std::shared_ptr<const Shape> make_bowl(double outer_radius, double inner_radius);

/// The rounded box (Suffern's beveled box): the points within `radius` of the box
/// [lower + radius, upper - radius], so its faces lie on [lower, upper] and every edge and
/// corner is rounded with `radius`. The union of three slabs, twelve edge cylinders and eight
/// corner spheres (make_union: no internal surface remains). Needs 0 < 2 radius < every extent.
std::shared_ptr<const Shape> make_rounded_box(const Point3& lower, const Point3& upper,
                                              double radius);

}  // namespace csgrt
