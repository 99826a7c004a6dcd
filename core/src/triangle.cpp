#include "csgrt/core/triangle.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "csgrt/core/error.h"
#include "csgrt/core/plane.h"
#include "flat_shape.h"

namespace csgrt {

Triangle::Triangle(const Point3& p0, const Point3& p1, const Point3& p2) : vertices_{p0, p1, p2} {
    require_finite(p0, "Triangle", "p0");
    require_finite(p1, "Triangle", "p1");
    require_finite(p2, "Triangle", "p2");
    // Edges scaled to O(1) first, so the cross product of tiny or huge edges cannot underflow
    // or overflow; only its direction is kept.
    const Vector3 edge_a = p1 - p0, edge_b = p2 - p0;
    const double scale_a = edge_a.cwiseAbs().maxCoeff(), scale_b = edge_b.cwiseAbs().maxCoeff();
    if (scale_a > 0.0 && scale_b > 0.0)
        normal_ = detail::normalized_or_zero((edge_a / scale_a).cross(edge_b / scale_b));
    else
        normal_ = Normal3::Zero();
    require(normal_.squaredNorm() > 0.0, "Triangle", "p0, p1, p2",
            "the corners of a triangle of non-zero area (not collinear)",
            detail::describe(p0) + ", " + detail::describe(p1) + ", " + detail::describe(p2));
}

Aabb Triangle::bounds() const {
    Aabb box(vertices_[0], vertices_[1]);
    box.extend(vertices_[2]);
    return box;
}

namespace {

/// The watertight test on the corners a, b, c relative to the ray's origin, for t in
/// [t_min, t_max]. Sets `overflow` (and reports nothing) when t's numerator is not finite.
inline std::optional<Crossing> watertight_crossing(const Vector3& a, const Vector3& b,
                                                   const Vector3& c, const Vector3& direction,
                                                   double t_min, double t_max, bool& overflow) {
    // Woop, Benthin and Wald 2013: move the origin to 0, make the dominant direction axis z
    // (so the shear never divides by a small number) and shear x and y so the ray runs along
    // +z. The ray is then the point (0, 0) and the test is a 2D point-in-triangle test. x and
    // y follow z cyclically; the winding this may flip is carried by the sign of det.
    const int kz = max_dimension(direction);
    const int kx = (kz + 1) % 3;
    const int ky = (kx + 1) % 3;
    const double shear_x = direction[kx] / direction[kz];
    const double shear_y = direction[ky] / direction[kz];
    const double shear_z = 1.0 / direction[kz];

    // Each vertex is transformed by the same operations whichever triangle it belongs to, so
    // neighbours see identical coordinates for their shared vertices: that is what makes the
    // test watertight.
    const double ax = a[kx] - shear_x * a[kz], ay = a[ky] - shear_y * a[kz];
    const double bx = b[kx] - shear_x * b[kz], by = b[ky] - shear_y * b[kz];
    const double cx = c[kx] - shear_x * c[kz], cy = c[ky] - shear_y * c[kz];

    // Edge functions (twice the signed areas of the origin with each edge). Kahan's 2x2
    // determinant has relative error <= 2u (Jeannerod, Louvet and Muller, "Further analysis of
    // Kahan's algorithm for the accurate computation of 2x2 determinants", Math. Comp. 2013), so
    // barring underflow each sign is the exact sign for these coordinates and a 0 is an exact
    // 0. That is why there is no fallback when an edge function is 0, unlike the float test in
    // the paper: recomputing in higher precision from the same inputs would give the same sign.
    double e0 = difference_of_products(bx, cy, by, cx);
    double e1 = difference_of_products(cx, ay, cy, ax);
    double e2 = difference_of_products(ax, by, ay, bx);
    // Mixed signs: the ray passes outside. Zeros count as inside, so edges are shared.
    if ((e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0)) return {};
    // The e_i share a sign, so det == 0 only when all are 0: a ray in the triangle's plane.
    double det = e0 + e1 + e2;
    if (det == 0.0) return {};

    const double az = shear_z * a[kz], bz = shear_z * b[kz], cz = shear_z * c[kz];
    double t_scaled = e0 * az + e1 * bz + e2 * cz;
    if (!std::isfinite(t_scaled)) {
        overflow = true;
        return {};
    }
    if (det < 0.0) {
        det = -det;
        t_scaled = -t_scaled;
        e1 = -e1;
        e2 = -e2;
    }
    // Division-free culling against the interval (t = t_scaled / det). The bounds t * det are
    // widened by three ulps, more than their own rounding plus that of the division, so a
    // triangle is culled only when the divided t would be outside too (barring underflow):
    // the decision itself is made on the divided t, like every other shape's.
    const double upper = t_max * det, lower = t_min * det;
    if (t_scaled > next_up(next_up(next_up(upper))) ||
        t_scaled < next_down(next_down(next_down(lower))))
        return {};
    const double t = t_scaled / det;
    if (!(t >= t_min && t <= t_max)) return {};
    return Crossing{.t = t, .u = static_cast<float>(e1 / det), .v = static_cast<float>(e2 / det)};
}

/// The slow path of Triangle::crossing for corners whose coordinates overflow t's numerator.
[[gnu::noinline]] std::optional<Crossing> scaled_crossing(const Vector3& a, const Vector3& b,
                                                          const Vector3& c, const Ray& ray) {
    bool overflow = false;
    // Coordinates beyond about 2^340 overflow the cubic numerator of t (a hit at infinity, or
    // NaN). Scaling them by a power of two is exact, keeps every edge function's sign (so the
    // test stays watertight) and the barycentrics, and divides t by the same power.
    const double extent =
        std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff()});
    if (!std::isfinite(extent)) return {};
    const int exponent = std::ilogb(extent);
    const double scale = std::ldexp(1.0, -exponent);
    std::optional<Crossing> scaled = watertight_crossing(
        a * scale, b * scale, c * scale, ray.direction, std::ldexp(ray.t_min, -exponent),
        std::ldexp(ray.t_max, -exponent), overflow);
    if (scaled) scaled->t = std::ldexp(scaled->t, exponent);
    return scaled;
}

}  // namespace

std::optional<Crossing> Triangle::crossing(const Ray& ray) const {
    const Vector3 a = vertices_[0] - ray.origin;
    const Vector3 b = vertices_[1] - ray.origin;
    const Vector3 c = vertices_[2] - ray.origin;
    bool overflow = false;
    const std::optional<Crossing> crossing =
        watertight_crossing(a, b, c, ray.direction, ray.t_min, ray.t_max, overflow);
    if (!overflow) [[likely]]
        return crossing;
    return scaled_crossing(a, b, c, ray);
}

SurfacePoint Triangle::surface_at(const Ray& ray, const HitRecord& record) const {
    Vector3 offset = ray.at(record.t) - vertices_[0];
    return {detail::onto_plane(vertices_[0], offset, normal_), normal_, detail::record_uv(record)};
}

template class detail::LeafShape<Triangle>;

}  // namespace csgrt
