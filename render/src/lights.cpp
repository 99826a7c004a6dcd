#include "csgrt/render/lights.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <variant>

#include <Eigen/Geometry>

#include "csgrt/render/sampling.h"

namespace csgrt {

namespace {

/// Two unit vectors perpendicular to unit `n` and to each other (Duff et al., "Building an
/// Orthonormal Basis, Revisited", JCGT 2017).
void orthonormal_basis(const Vector3& n, Vector3& t1, Vector3& t2) {
    const double sign = std::copysign(1.0, n.z());
    const double a = -1.0 / (sign + n.z());
    const double b = n.x() * n.y() * a;
    t1 = Vector3(1.0 + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
    t2 = Vector3(b, sign + n.y() * n.y() * a, -n.y());
}

/// A sample on an emitting surface element of area `area` with unit normal `normal`: the
/// area-measure estimator L cos_light / d^2 * area / samples.
std::optional<LightSample> surface_sample(const Point3& point, const Point3& on_light,
                                          const Vector3& normal, double area,
                                          const Vector3& radiance, int samples) {
    const Vector3 offset = on_light - point;
    const double distance_squared = offset.squaredNorm();
    if (!(distance_squared > 0.0)) return std::nullopt;
    const Vector3 to_light = offset / std::sqrt(distance_squared);
    const double cos_light = -normal.dot(to_light);
    if (!(cos_light > 0.0)) return std::nullopt;  // the point is behind the emitting side
    return LightSample{to_light, radiance * (cos_light * area / (distance_squared * samples)),
                       on_light};
}

/// Shirley and Chiu's concentric map from [0, 1)^2 onto the unit disk.
Vector2 concentric_disk(const Vector2& u) {
    const Vector2 p = 2.0 * u - Vector2(1.0, 1.0);
    if (p.x() == 0.0 && p.y() == 0.0) return Vector2::Zero();
    double radius;
    double angle;
    if (std::abs(p.x()) > std::abs(p.y())) {
        radius = p.x();
        angle = (kPi / 4.0) * (p.y() / p.x());
    } else {
        radius = p.y();
        angle = kPi / 2.0 - (kPi / 4.0) * (p.x() / p.y());
    }
    return radius * Vector2(std::cos(angle), std::sin(angle));
}

}  // namespace

int light_sample_count(const Light& light) {
    if (const auto* rectangle = std::get_if<RectangleLight>(&light)) return rectangle->samples;
    if (const auto* disk = std::get_if<DiskLight>(&light)) return disk->samples;
    if (const auto* sphere = std::get_if<SphereLight>(&light)) return sphere->samples;
    return 1;
}

std::optional<LightSample> sample_light(const Light& light, const Point3& point, const Vector2& u) {
    if (const auto* rectangle = std::get_if<RectangleLight>(&light)) {
        const Vector3 cross = rectangle->edge_u.cross(rectangle->edge_v);
        const double area = cross.norm();
        const Point3 on_light =
            rectangle->corner + u.x() * rectangle->edge_u + u.y() * rectangle->edge_v;
        return surface_sample(point, on_light, cross / area, area, rectangle->radiance,
                              rectangle->samples);
    }
    if (const auto* disk = std::get_if<DiskLight>(&light)) {
        const Vector3 normal = disk->normal.normalized();
        Vector3 t1;
        Vector3 t2;
        orthonormal_basis(normal, t1, t2);
        const Vector2 d = disk->radius * concentric_disk(u);
        return surface_sample(point, disk->centre + d.x() * t1 + d.y() * t2, normal,
                              kPi * disk->radius * disk->radius, disk->radiance, disk->samples);
    }
    if (const auto* sphere = std::get_if<SphereLight>(&light)) {
        const Vector3 offset = sphere->centre - point;
        const double distance_squared = offset.squaredNorm();
        const double radius_squared = sphere->radius * sphere->radius;
        if (!(distance_squared > radius_squared)) return std::nullopt;  // inside: unlit
        const double distance = std::sqrt(distance_squared);
        const Vector3 axis = offset / distance;
        // The cone of directions toward the ball: cos(theta_max) = sqrt(1 - r^2 / d^2),
        // uniform in solid angle Omega = 2 pi (1 - cos(theta_max)), so each sample brings
        // L Omega / samples.
        const double sin2_max = radius_squared / distance_squared;
        const double cos_max = std::sqrt(std::max(0.0, 1.0 - sin2_max));
        // 1 - cos_max without cancellation for small balls far away.
        const double one_minus_cos_max = sin2_max / (1.0 + cos_max);
        const double cos_theta = 1.0 - u.x() * one_minus_cos_max;
        const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
        const double phi = kTwoPi * u.y();
        Vector3 t1;
        Vector3 t2;
        orthonormal_basis(axis, t1, t2);
        const Vector3 to_light =
            (cos_theta * axis + sin_theta * (std::cos(phi) * t1 + std::sin(phi) * t2)).normalized();
        // The nearer root of |point + s to_light - centre| = r, clamped at the tangent.
        const double along = to_light.dot(offset);
        const double across2 = std::max(0.0, radius_squared - (distance_squared - along * along));
        const double reach = along - std::sqrt(across2);
        const double solid_angle = kTwoPi * one_minus_cos_max;
        return LightSample{to_light, sphere->radiance * (solid_angle / sphere->samples),
                           point + reach * to_light};
    }
    return std::nullopt;
}

std::uint64_t light_sample_seed(const Point3& point, std::uint64_t seed, std::size_t light) {
    SampleRandom mix(seed ^ (kSplitMixIncrement * (light + 1)));
    std::uint64_t hash = mix.next_bits();
    for (int i = 0; i < 3; ++i) {
        SampleRandom step(hash ^ std::bit_cast<std::uint64_t>(point[i]));
        hash = step.next_bits();
    }
    return hash;
}

}  // namespace csgrt
