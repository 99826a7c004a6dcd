#include "csgrt/core/transform.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "csgrt/core/error.h"

namespace csgrt {

Transform::Transform()
    : linear_(Eigen::Matrix3d::Identity()),
      translation_(Vector3::Zero()),
      inverse_linear_(Eigen::Matrix3d::Identity()),
      inverse_translation_(Vector3::Zero()) {}

Transform::Transform(const Eigen::Matrix3d& linear, const Vector3& translation)
    : linear_(linear), translation_(translation) {
    require(linear.allFinite(), "Transform", "every matrix entry", "finite",
            linear.reshaped().eval());
    require_finite(translation, "Transform", "translation");
    const double column_lengths =
        linear.col(0).norm() * linear.col(1).norm() * linear.col(2).norm();
    const double determinant = linear.determinant();
    // Hadamard: |det| <= product of column lengths, with equality for orthogonal columns.
    const double conditioning = column_lengths > 0.0 ? std::abs(determinant) / column_lengths : 0.0;
    require(conditioning >= 1e-12, "Transform", "matrix",
            "invertible (|det| / product of column lengths >= 1e-12)", conditioning);
    inverse_linear_ = linear.inverse();
    inverse_translation_ = -(inverse_linear_ * translation);
}

Transform Transform::from_matrix(const Eigen::Matrix4d& matrix) {
    require(matrix.allFinite(), "Transform", "every matrix entry", "finite",
            matrix.reshaped().eval());
    const Eigen::RowVector4d last_row = matrix.row(3);
    require(last_row == Eigen::RowVector4d(0, 0, 0, 1), "Transform", "last matrix row",
            "(0, 0, 0, 1) for an affine map", last_row.transpose().eval());
    return Transform(matrix.topLeftCorner<3, 3>(), matrix.topRightCorner<3, 1>());
}

Transform Transform::translate(const Vector3& offset) {
    require_finite(offset, "Transform::translate", "offset");
    return Transform(Eigen::Matrix3d::Identity(), offset, Eigen::Matrix3d::Identity(), -offset);
}

Transform Transform::scale(const Vector3& factors) {
    require(factors.allFinite() && (factors.array() != 0.0).all(), "Transform::scale", "factors",
            "finite and non-zero", factors);
    return Transform(factors.asDiagonal().toDenseMatrix(), Vector3::Zero(),
                     factors.cwiseInverse().asDiagonal().toDenseMatrix(), Vector3::Zero());
}

Transform Transform::rotate(const Vector3& axis, double radians) {
    require(axis.allFinite() && axis.squaredNorm() > 0.0, "Transform::rotate", "axis",
            "finite and non-zero", axis);
    require_finite(radians, "Transform::rotate", "angle");
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(radians, axis.normalized()).toRotationMatrix();
    // The inverse of a rotation is its transpose: exact, no solve.
    return Transform(rotation, Vector3::Zero(), rotation.transpose(), Vector3::Zero());
}

Transform Transform::shear(int axis, int by_axis, double factor) {
    require(axis >= 0 && axis < 3, "Transform::shear", "axis", "0, 1 or 2", axis);
    require(by_axis >= 0 && by_axis < 3 && by_axis != axis, "Transform::shear", "by_axis",
            "0, 1 or 2 and different from axis", by_axis);
    require_finite(factor, "Transform::shear", "factor");
    Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
    linear(axis, by_axis) = factor;
    Eigen::Matrix3d inverse = Eigen::Matrix3d::Identity();
    inverse(axis, by_axis) = -factor;
    return Transform(linear, Vector3::Zero(), inverse, Vector3::Zero());
}

Transform Transform::operator*(const Transform& other) const {
    // (A, a) after (B, b): p -> A (B p + b) + a; the inverse composes the other way round.
    return Transform(linear_ * other.linear_, linear_ * other.translation_ + translation_,
                     other.inverse_linear_ * inverse_linear_,
                     other.inverse_linear_ * inverse_translation_ + other.inverse_translation_);
}

Transform Transform::inverse() const {
    return Transform(inverse_linear_, inverse_translation_, linear_, translation_);
}

Aabb Transform::apply(const Aabb& box) const {
    if (box.is_empty()) return box;
    Aabb result;
    result.lower = translation_;
    result.upper = translation_;
    for (int row = 0; row < 3; ++row) {
        double magnitude = std::abs(translation_[row]);
        for (int column = 0; column < 3; ++column) {
            const double m = linear_(row, column);
            if (m == 0.0) continue;  // keeps 0 * inf from poisoning infinite boxes
            const double a = m * box.lower[column];
            const double b = m * box.upper[column];
            result.lower[row] += std::min(a, b);
            result.upper[row] += std::max(a, b);
            magnitude += std::max(std::abs(a), std::abs(b));
        }
        // Pad by the rounding bound of three products and three sums, so a point of the object
        // mapped by apply_point never falls outside its transformed box.
        const double pad = gamma(4) * magnitude;
        result.lower[row] -= pad;
        result.upper[row] += pad;
    }
    return result;
}

Eigen::Matrix4d Transform::matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = linear_;
    m.topRightCorner<3, 1>() = translation_;
    return m;
}

bool Transform::is_identity() const {
    return linear_ == Eigen::Matrix3d::Identity() && translation_ == Vector3::Zero();
}

}  // namespace csgrt
