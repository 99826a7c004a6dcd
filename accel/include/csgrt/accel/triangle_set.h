#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "csgrt/core/aabb.h"
#include "csgrt/core/hit.h"
#include "csgrt/core/query_scratch.h"
#include "csgrt/core/ray.h"

namespace csgrt {

/// A triangle soup stored for intersection speed: each triangle's three vertices side by side
/// in `Real` precision (float: 36 bytes a triangle, as fast renderers store them; double: 72),
/// in the order given. Models PrimitiveSet. Hits are found with the watertight test of Woop,
/// Benthin and Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1) 2013: a ray through a
/// shared edge or vertex hits at least one of the triangles that share it, in either precision.
template <class Real>
class TriangleSet {
public:
    using Vector = Eigen::Matrix<Real, 3, 1>;

    /// The ray in the triangle test's frame: origin, the permutation that makes z the dominant
    /// direction axis, and the shear that maps the direction to (0, 0, 1). shear_x and shear_y
    /// are ratios of direction components (scale-free, so they fit Real for any valid ray);
    /// shear_z = 1 / d_z stays in double, where a direction of length 1e-150 or 1e150 (valid,
    /// see is_valid) does not overflow or underflow as it would in float.
    struct PreparedRay {
        Vector origin;
        int axis_x, axis_y, axis_z;
        Real shear_x, shear_y;
        double shear_z;
        double t_min, t_max;
    };

    TriangleSet() = default;
    /// Copies the triangles' corners (converted to Real). Indices must be in range; the caller
    /// (the mesh loader) has validated them.
    TriangleSet(std::span<const Eigen::Vector3d> vertices,
                std::span<const std::array<std::uint32_t, 3>> triangles);

    std::size_t size() const { return corners_.size(); }
    /// Exact box of the stored (rounded) corners: converting float to double is exact.
    Aabb bounds(std::size_t i) const;
    Point3 centroid(std::size_t i) const;
    /// Corner k (0..2) of triangle i, as stored.
    const Vector& corner(std::size_t i, int k) const { return corners_[i][k]; }

    PreparedRay prepare(const Ray& ray, QueryScratch& scratch) const;
    /// Woop's test; ties at equal t go to the lower triangle index. Writes t, primitive = i
    /// and the barycentrics of corners 1 and 2 in u, v.
    bool intersect(std::size_t i, const PreparedRay& ray, HitRecord& record) const;
    bool occluded(std::size_t i, const PreparedRay& ray) const;

    /// A triangle in the test's frame: corner k at (x[k], y[k]) after the shear, and z[k], its
    /// coordinate along the dominant axis relative to the origin, not yet scaled.
    struct ShearedTriangle {
        Real x[3], y[3], z[3];
    };
    /// Triangle i in the frame of `ray`: corner - origin, then x -= shear_x z, y -= shear_y z.
    ShearedTriangle shear(std::size_t i, const PreparedRay& ray) const;
    /// The rest of Woop's test: t and the barycentric weights of corners 1 and 2 of the hit, or
    /// false for a miss. A SIMD test of several triangles (the BVH's leaves) shears them with
    /// the same float operations lane by lane and calls this for every lane it keeps; it may
    /// drop a lane early only when that lane's three edge functions (computed as below) are
    /// non-zero and of mixed signs (or one is NaN: t is then NaN, which no query keeps), and it
    /// may finish the other lanes itself where no edge function is zero, with the double
    /// arithmetic below in the same order. Its answers are then the very bits of `intersect`'s.
    static bool hit_sheared(const ShearedTriangle& triangle, double shear_z, double& t, double& b1,
                            double& b2);
    /// Writes the hit of triangle `index` at t into `record` when it lies in [t_min, record.t]
    /// and beats the record under the tie rule (lower index at equal t); returns whether it did.
    static bool keep_nearest(std::uint32_t index, double t, double b1, double b2,
                             const PreparedRay& ray, HitRecord& record);

    std::size_t bytes() const { return corners_.capacity() * sizeof(corners_[0]); }

private:
    std::vector<std::array<Vector, 3>> corners_;
};

// The test is defined here, inline, so that structures can inline it into their loops. Every
// caller must compile it without floating-point contraction (accel/CMakeLists.txt passes
// -ffp-contract=off to every target that uses csgrt::accel), so its rounding is the same
// everywhere.

template <class Real>
inline typename TriangleSet<Real>::PreparedRay TriangleSet<Real>::prepare(const Ray& ray,
                                                                   QueryScratch&) const {
    PreparedRay prepared;
    prepared.origin = ray.origin.cast<Real>();
    // z is the dominant direction axis, so the shear never divides by a small number; x and y
    // follow cyclically (the winding is carried by the sign of det, not by a swap).
    prepared.axis_z = max_dimension(ray.direction);
    prepared.axis_x = prepared.axis_z == 2 ? 0 : prepared.axis_z + 1;
    prepared.axis_y = prepared.axis_x == 2 ? 0 : prepared.axis_x + 1;
    // The ratios are formed in double and rounded once.
    const Vector3& direction = ray.direction;
    prepared.shear_z = 1.0 / direction[prepared.axis_z];
    prepared.shear_x = static_cast<Real>(direction[prepared.axis_x] / direction[prepared.axis_z]);
    prepared.shear_y = static_cast<Real>(direction[prepared.axis_y] / direction[prepared.axis_z]);
    prepared.t_min = ray.t_min;
    prepared.t_max = ray.t_max;
    return prepared;
}

template <class Real>
inline typename TriangleSet<Real>::ShearedTriangle TriangleSet<Real>::shear(
    std::size_t i, const PreparedRay& ray) const {
    const auto& c = corners_[i];
    const int kx = ray.axis_x, ky = ray.axis_y, kz = ray.axis_z;
    ShearedTriangle sheared;
    for (int k = 0; k < 3; ++k) {
        // Corners relative to the origin, sheared so the ray runs along +z from (0, 0, 0).
        const Vector p = c[k] - ray.origin;
        sheared.x[k] = p[kx] - ray.shear_x * p[kz];
        sheared.y[k] = p[ky] - ray.shear_y * p[kz];
        sheared.z[k] = p[kz];
    }
    return sheared;
}

template <class Real>
inline bool TriangleSet<Real>::hit_sheared(const ShearedTriangle& triangle, double shear_z,
                                           double& t, double& b1, double& b2) {
    const Real ax = triangle.x[0], ay = triangle.y[0];
    const Real bx = triangle.x[1], by = triangle.y[1];
    const Real cx = triangle.x[2], cy = triangle.y[2];
    // Edge functions: twice the signed areas of the ray's footprint with each edge. Triangles
    // that share an edge compute that edge's function from identical inputs, identically.
    Real u = cx * by - cy * bx;
    Real v = ax * cy - ay * cx;
    Real w = bx * ay - by * ax;
    if constexpr (std::is_same_v<Real, float>) {
        // An exact zero in float may be a rounding artefact; redo those products in double,
        // which is exact for products of floats (Woop et al., section 3).
        if (u == 0.0f || v == 0.0f || w == 0.0f) {
            u = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
            v = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
            w = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
        }
    }
    // Mixed signs: the footprint is outside. Zeros count as inside, so edges are shared.
    if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return false;
    const Real determinant = u + v + w;
    if (determinant == Real(0)) return false;  // edge-on or degenerate
    // Woop's T = U Az + V Bz + W Cz with Az = z / d_z, formed in double: for a valid ray 1 / d_z
    // may lie outside float's range (|d| = 1e-150), and with float triangles at tiny scales the
    // products would underflow. For double triangles this is Woop's arithmetic exactly.
    const double az = shear_z * double(triangle.z[0]), bz = shear_z * double(triangle.z[1]),
                 cz = shear_z * double(triangle.z[2]);
    const double scaled_t = double(u) * az + double(v) * bz + double(w) * cz;
    // The division happens only for triangles the ray crosses; comparing t itself (not the
    // scaled form) keeps the tie rule exact. The determinant is summed in double too (u, v, w
    // share a sign here, so it cannot cancel), so that a ray meeting a triangle at constant z
    // gets t = az exactly, as in Woop's all-float arithmetic.
    const double inverse = 1.0 / (double(u) + double(v) + double(w));
    t = scaled_t * inverse;
    b1 = double(v) * inverse;
    b2 = double(w) * inverse;
    return true;
}

template <class Real>
inline bool TriangleSet<Real>::keep_nearest(std::uint32_t index, double t, double b1, double b2,
                                            const PreparedRay& ray, HitRecord& record) {
    if (!(t >= ray.t_min && (t < record.t || (t == record.t && index < record.primitive))))
        return false;
    record.t = t;
    record.primitive = index;
    record.u = static_cast<float>(b1);
    record.v = static_cast<float>(b2);
    return true;
}

template <class Real>
inline bool TriangleSet<Real>::intersect(std::size_t i, const PreparedRay& ray,
                                         HitRecord& record) const {
    double t, b1, b2;
    if (!hit_sheared(shear(i, ray), ray.shear_z, t, b1, b2)) return false;
    return keep_nearest(static_cast<std::uint32_t>(i), t, b1, b2, ray, record);
}

template <class Real>
inline bool TriangleSet<Real>::occluded(std::size_t i, const PreparedRay& ray) const {
    double t, b1, b2;
    return hit_sheared(shear(i, ray), ray.shear_z, t, b1, b2) && t >= ray.t_min && t <= ray.t_max;
}

extern template class TriangleSet<float>;
extern template class TriangleSet<double>;

}  // namespace csgrt
