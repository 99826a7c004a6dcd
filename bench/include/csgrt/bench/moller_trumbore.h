#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "csgrt/core/hit.h"
#include "csgrt/core/ray.h"

namespace csgrt::bench {

/// The ray-triangle test of Moeller and Trumbore, "Fast, Minimum Storage Ray-Triangle
/// Intersection", JGT 2(1) 1997, as published (no back-face culling, |det| < 1e-6 rejected),
/// in `Real` arithmetic: the benchmark's comparison variant for the library's watertight test.
/// Each triangle computes its barycentrics from its own first corner and edges, so a ray
/// through an edge shared by two triangles can miss both (a crack) or hit both; the benchmark
/// measures how often. Not part of the library.
template <class Real>
class MollerTrumbore {
public:
    using Vector = Eigen::Matrix<Real, 3, 1>;

    /// The paper's EPSILON, absolute: near-parallel rays and tiny or thin triangles are
    /// rejected by it.
    static constexpr Real kEpsilon = Real(1e-6);

    /// The ray in Real precision.
    struct PreparedRay {
        Vector origin;
        Vector direction;
        double t_min, t_max;
    };

    static PreparedRay prepare(const Ray& ray) {
        return {ray.origin.cast<Real>(), ray.direction.cast<Real>(), ray.t_min, ray.t_max};
    }

    /// Whether the ray hits triangle (a, b, c) at a t in [t_min, t_max]; writes t and the
    /// barycentrics (u, v) of b and c.
    static bool hit(const Vector& a, const Vector& b, const Vector& c, const PreparedRay& ray,
                    double& t, double& u, double& v) {
        const Vector edge1 = b - a;
        const Vector edge2 = c - a;
        const Vector p = ray.direction.cross(edge2);
        const Real determinant = edge1.dot(p);
        if (determinant > -kEpsilon && determinant < kEpsilon) return false;
        const Real inverse = Real(1) / determinant;
        const Vector s = ray.origin - a;
        const Real bary_u = s.dot(p) * inverse;
        if (bary_u < Real(0) || bary_u > Real(1)) return false;
        const Vector q = s.cross(edge1);
        const Real bary_v = ray.direction.dot(q) * inverse;
        if (bary_v < Real(0) || bary_u + bary_v > Real(1)) return false;
        const Real t_hit = edge2.dot(q) * inverse;
        if (!(t_hit >= ray.t_min && t_hit <= ray.t_max)) return false;
        t = t_hit;
        u = bary_u;
        v = bary_v;
        return true;
    }
};

}  // namespace csgrt::bench
