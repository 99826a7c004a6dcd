#include "csgrt/csg/ready_made.h"

#include <Eigen/Geometry>
#include <vector>

#include "csgrt/core/box.h"
#include "csgrt/core/cone.h"
#include "csgrt/core/cylinder.h"
#include "csgrt/core/error.h"
#include "csgrt/core/instance.h"
#include "csgrt/core/sphere.h"
#include "csgrt/core/transform.h"
#include "csgrt/csg/boolean.h"

namespace csgrt {

namespace {

/// A rotation taking +y to the unit vector `axis`. An axis along a coordinate axis gets an
/// exact signed permutation (e_x -> s e_j, e_y -> s e_k, e_z -> e_i with (k, i, j) cyclic),
/// so axis-aligned pieces keep exact coordinates; any other axis the shortest rotation.
Eigen::Matrix3d rotation_from_y(const Vector3& axis) {
    for (int k = 0; k < 3; ++k) {
        const int i = (k + 1) % 3;
        const int j = (k + 2) % 3;
        if (axis[i] != 0.0 || axis[j] != 0.0) continue;
        const double s = axis[k] > 0.0 ? 1.0 : -1.0;
        Eigen::Matrix3d rotation = Eigen::Matrix3d::Zero();
        rotation(j, 0) = s;
        rotation(k, 1) = s;
        rotation(i, 2) = 1.0;
        return rotation;
    }
    return Eigen::Quaterniond::FromTwoVectors(Vector3(0, 1, 0), axis).toRotationMatrix();
}

/// `shape` (built along +y from y = 0) standing on `base` with its axis toward `top`.
std::shared_ptr<const Shape> stand(std::shared_ptr<const Shape> shape, const Point3& base,
                                   const Vector3& axis) {
    return std::make_shared<Instance>(std::move(shape),
                                      Transform(rotation_from_y(axis.normalized()), base));
}

/// The length of top - base, checked: both ends finite and distinct.
double axis_length(const Point3& base, const Point3& top, std::string_view what) {
    require_finite(base, what, "bottom");
    require_finite(top, what, "top");
    const double length = (top - base).norm();
    require(length > 0.0 && std::isfinite(length), what, "top", "different from the bottom", top);
    return length;
}

}  // namespace

std::shared_ptr<const Shape> make_solid_cylinder(const Point3& bottom, const Point3& top,
                                                 double radius) {
    constexpr std::string_view kWhat = "make_solid_cylinder";
    require_positive(radius, kWhat, "radius");
    const Vector3 axis = top - bottom;
    // Along +-y the cylinder is built at the right heights and only moved sideways (exact).
    if (axis.x() == 0.0 && axis.z() == 0.0) {
        axis_length(bottom, top, kWhat);
        auto cylinder = std::make_shared<Cylinder>(radius, std::min(bottom.y(), top.y()),
                                                   std::max(bottom.y(), top.y()), true);
        if (bottom.x() == 0.0 && bottom.z() == 0.0) return cylinder;
        return std::make_shared<Instance>(
            cylinder, Transform::translate(Vector3(bottom.x(), 0.0, bottom.z())));
    }
    const double length = axis_length(bottom, top, kWhat);
    return stand(std::make_shared<Cylinder>(radius, 0.0, length, true), bottom, axis);
}

std::shared_ptr<const Shape> make_solid_cone(const Point3& base, const Point3& top,
                                             double base_radius, double top_radius) {
    const double length = axis_length(base, top, "make_solid_cone");
    return stand(std::make_shared<Cone>(base_radius, top_radius, length, true), base, top - base);
}

std::shared_ptr<const Shape> make_thick_ring(double y_min, double y_max, double inner_radius,
                                             double outer_radius) {
    constexpr std::string_view kWhat = "make_thick_ring";
    require_finite(y_min, kWhat, "y_min");
    require(y_max > y_min && std::isfinite(y_max), kWhat, "y_max", "finite and > y_min", y_max);
    require_positive(inner_radius, kWhat, "inner_radius");
    require(outer_radius > inner_radius && std::isfinite(outer_radius), kWhat, "outer_radius",
            "finite and > inner_radius", outer_radius);
    const double height = y_max - y_min;
    auto outer = std::make_shared<Cylinder>(outer_radius, y_min, y_max, true);
    // The hole reaches half the height beyond each end, away from the caps it cuts through.
    auto hole =
        std::make_shared<Cylinder>(inner_radius, y_min - 0.5 * height, y_max + 0.5 * height, true);
    return std::make_shared<Boolean>(BooleanOperation::Difference, outer, hole);
}

std::shared_ptr<const Shape> make_bowl(double outer_radius, double inner_radius) {
    constexpr std::string_view kWhat = "make_bowl";
    require_positive(inner_radius, kWhat, "inner_radius");
    require(outer_radius > inner_radius && std::isfinite(outer_radius), kWhat, "outer_radius",
            "finite and > inner_radius", outer_radius);
    auto ball = std::make_shared<Sphere>(Point3(0, 0, 0), outer_radius);
    auto hollow = std::make_shared<Sphere>(Point3(0, 0, 0), inner_radius);
    auto shell = std::make_shared<Boolean>(BooleanOperation::Difference, ball, hollow);
    // The lower half-space, as a solid wider and deeper than the ball: only its top cap (the
    // rim) ever becomes part of the bowl's surface.
    auto below = std::make_shared<Cylinder>(2.0 * outer_radius, -2.0 * outer_radius, 0.0, true);
    return std::make_shared<Boolean>(BooleanOperation::Intersection, shell, below);
}

std::shared_ptr<const Shape> make_rounded_box(const Point3& lower, const Point3& upper,
                                              double radius) {
    constexpr std::string_view kWhat = "make_rounded_box";
    require_finite(lower, kWhat, "lower");
    require_finite(upper, kWhat, "upper");
    require_positive(radius, kWhat, "radius");
    require(((upper - lower).array() > 2.0 * radius).all(), kWhat, "upper",
            "beyond lower + 2 radius on every axis", upper);
    const Point3 inner_lower = lower + Vector3::Constant(radius);
    const Point3 inner_upper = upper - Vector3::Constant(radius);
    std::vector<std::shared_ptr<const Shape>> pieces;
    // Three slabs, each the inner box reaching out to the faces along one axis.
    for (int axis = 0; axis < 3; ++axis) {
        Point3 slab_lower = inner_lower;
        Point3 slab_upper = inner_upper;
        slab_lower[axis] = lower[axis];
        slab_upper[axis] = upper[axis];
        pieces.push_back(std::make_shared<Box>(slab_lower, slab_upper));
    }
    // Twelve edge cylinders along the inner box's edges, and its eight corner spheres.
    for (int axis = 0; axis < 3; ++axis) {
        for (int corner = 0; corner < 4; ++corner) {
            Point3 from = inner_lower;
            from[(axis + 1) % 3] =
                (corner & 1) ? inner_upper[(axis + 1) % 3] : inner_lower[(axis + 1) % 3];
            from[(axis + 2) % 3] =
                (corner & 2) ? inner_upper[(axis + 2) % 3] : inner_lower[(axis + 2) % 3];
            Point3 to = from;
            to[axis] = inner_upper[axis];
            pieces.push_back(make_solid_cylinder(from, to, radius));
        }
    }
    for (int corner = 0; corner < 8; ++corner) {
        const Point3 centre((corner & 1) ? inner_upper.x() : inner_lower.x(),
                            (corner & 2) ? inner_upper.y() : inner_lower.y(),
                            (corner & 4) ? inner_upper.z() : inner_lower.z());
        pieces.push_back(std::make_shared<Sphere>(centre, radius));
    }
    return make_union(pieces);
}

}  // namespace csgrt
