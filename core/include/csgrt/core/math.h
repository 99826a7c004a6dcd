#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>

namespace csgrt {

/// Points, vectors and normals are all Eigen 3-vectors of double; the names say which one a
/// value is, and `Transform` has one function per kind (points translate, normals use the
/// inverse transpose).
using Vector3 = Eigen::Vector3d;
using Point3 = Eigen::Vector3d;
using Normal3 = Eigen::Vector3d;
using Vector2 = Eigen::Vector2d;

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;

/// Half the distance from 1 to the next double: the unit roundoff of one IEEE operation.
inline constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() * 0.5;

/// gamma(n) = n u / (1 - n u) bounds the relative error of n chained double operations
/// (Higham, "Accuracy and Stability of Numerical Algorithms", 2002; pbrt-v4 uses the same bound).
constexpr double gamma(int n) {
    return n * kUnitRoundoff / (1.0 - n * kUnitRoundoff);
}

/// The same bound for single precision, for the float triangle and box tests.
constexpr float gamma_float(int n) {
    constexpr float u = std::numeric_limits<float>::epsilon() * 0.5f;
    return n * u / (1.0f - n * u);
}

constexpr double square(double x) {
    return x * x;
}

/// a*b - c*d with the rounding error of c*d compensated (Kahan's algorithm, via FMA); accurate
/// to about 1.5 ulp even when the two products nearly cancel.
inline double difference_of_products(double a, double b, double c, double d) {
    const double cd = c * d;
    const double error = std::fma(-c, d, cd);
    const double difference = std::fma(a, b, -cd);
    return difference + error;
}

inline bool is_finite(const Vector3& v) {
    return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

/// The next representable double above / below v (used to round error bounds outward).
inline double next_up(double v) {
    return std::nextafter(v, kInfinity);
}
inline double next_down(double v) {
    return std::nextafter(v, -kInfinity);
}

/// The largest axis of v's absolute components (ties go to the lower axis, deterministically).
inline int max_dimension(const Vector3& v) {
    const Vector3 a = v.cwiseAbs();
    return a.x() >= a.y() ? (a.x() >= a.z() ? 0 : 2) : (a.y() >= a.z() ? 1 : 2);
}

/// An index that names nothing: no primitive, no object, no instance path.
inline constexpr std::uint32_t kNoIndex = 0xffffffffu;

}  // namespace csgrt
