#pragma once

#include <Eigen/Core>

#include "csgrt/core/aabb.h"
#include "csgrt/core/math.h"
#include "csgrt/core/ray.h"

namespace csgrt {

/// An invertible affine map p -> L p + c (rotation, non-uniform scale, shear, translation),
/// stored with its inverse so both directions cost the same. Name instances by what they map
/// between: `world_from_object.apply_point(p_object)` gives a world point.
class Transform {
public:
    /// The identity.
    Transform();

    /// From the linear part L and translation c. Throws InvalidParameter when an entry is not
    /// finite or L is singular: |det L| / (product of L's column lengths) below 1e-12, a
    /// scale-free measure (Hadamard's inequality bounds it by 1) that rejects a collapsed axis
    /// however the other axes are scaled.
    Transform(const Eigen::Matrix3d& linear, const Vector3& translation);

    /// From a 4x4 matrix acting on column vectors; the last row must be (0, 0, 0, 1).
    static Transform from_matrix(const Eigen::Matrix4d& matrix);
    static Transform translate(const Vector3& offset);
    static Transform scale(const Vector3& factors);
    static Transform scale(double factor) { return scale(Vector3::Constant(factor)); }
    /// Rotation by `radians` about `axis` (any non-zero length), right-handed.
    static Transform rotate(const Vector3& axis, double radians);
    /// Shear that adds `factor` times coordinate `by_axis` to coordinate `axis` (0=x, 1=y, 2=z):
    /// shear(0, 1, k) maps (x, y, z) to (x + k y, y, z).
    static Transform shear(int axis, int by_axis, double factor);

    /// Composition: (a * b).apply_point(p) == a.apply_point(b.apply_point(p)).
    Transform operator*(const Transform& other) const;
    /// The inverse map; free, since both directions are stored.
    Transform inverse() const;

    Point3 apply_point(const Point3& p) const { return linear_ * p + translation_; }
    Vector3 apply_vector(const Vector3& v) const { return linear_ * v; }
    /// Normals map by the inverse transpose so they stay perpendicular to the surface; the
    /// result is not normalised.
    Normal3 apply_normal(const Normal3& n) const { return inverse_linear_.transpose() * n; }
    /// Maps origin and direction; t_min, t_max and so every t are unchanged (no renormalising).
    Ray apply(const Ray& ray) const {
        return Ray{apply_point(ray.origin), apply_vector(ray.direction), ray.t_min, ray.t_max};
    }
    /// The box of the mapped box (Arvo, "Transforming Axis-Aligned Bounding Boxes", Graphics
    /// Gems 1990): exact for the 8 corners, without enumerating them. Infinite boxes stay
    /// infinite along every axis they touch.
    Aabb apply(const Aabb& box) const;

    const Eigen::Matrix3d& linear() const { return linear_; }
    const Vector3& translation() const { return translation_; }
    const Eigen::Matrix3d& inverse_linear() const { return inverse_linear_; }
    /// The 4x4 matrix acting on column vectors.
    Eigen::Matrix4d matrix() const;
    bool is_identity() const;

private:
    Transform(const Eigen::Matrix3d& linear, const Vector3& translation,
              const Eigen::Matrix3d& inverse_linear, const Vector3& inverse_translation)
        : linear_(linear),
          translation_(translation),
          inverse_linear_(inverse_linear),
          inverse_translation_(inverse_translation) {}

    Eigen::Matrix3d linear_;
    Vector3 translation_;
    Eigen::Matrix3d inverse_linear_;
    Vector3 inverse_translation_;
};

}  // namespace csgrt
