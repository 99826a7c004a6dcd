#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
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

    std::size_t bytes() const { return corners_.capacity() * sizeof(corners_[0]); }

private:
    /// t and barycentric weights (of corners 0, 1, 2, unnormalised, and their sum) of the hit
    /// of `ray` with triangle i, or false for a miss.
    bool hit(std::size_t i, const PreparedRay& ray, double& t, double& b1, double& b2) const;

    std::vector<std::array<Vector, 3>> corners_;
};

extern template class TriangleSet<float>;
extern template class TriangleSet<double>;

}  // namespace csgrt
