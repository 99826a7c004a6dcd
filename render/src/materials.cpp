#include "csgrt/render/materials.h"

#include <algorithm>
#include <cmath>

namespace csgrt {

Vector3 reflect(const Vector3& direction, const Normal3& normal) {
    return direction - 2.0 * direction.dot(normal) * normal;
}

std::optional<Vector3> refract(const Vector3& direction, const Normal3& normal, double eta) {
    const double cos_incident = std::min(1.0, -direction.dot(normal));
    const double sin2_transmitted = eta * eta * std::max(0.0, 1.0 - cos_incident * cos_incident);
    if (sin2_transmitted >= 1.0) return std::nullopt;
    const double cos_transmitted = std::sqrt(1.0 - sin2_transmitted);
    // pbrt-v4 eq. 9.4: the tangential part scaled by eta, the normal part set by cos_t.
    return (eta * direction + (eta * cos_incident - cos_transmitted) * normal).normalized();
}

double fresnel_dielectric(double cos_incident, double eta_incident, double eta_transmitted) {
    const double cos_i = std::clamp(cos_incident, 0.0, 1.0);
    const double eta = eta_incident / eta_transmitted;
    const double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) return 1.0;  // total internal reflection
    const double cos_t = std::sqrt(1.0 - sin2_t);
    const double parallel = (eta_transmitted * cos_i - eta_incident * cos_t) /
                            (eta_transmitted * cos_i + eta_incident * cos_t);
    const double perpendicular = (eta_incident * cos_i - eta_transmitted * cos_t) /
                                 (eta_incident * cos_i + eta_transmitted * cos_t);
    return 0.5 * (parallel * parallel + perpendicular * perpendicular);
}

double phong_lobe(const Vector3& to_light, const Vector3& to_viewer, const Normal3& normal,
                  double shininess) {
    const double cosine = reflect(-to_viewer, normal).dot(to_light);
    if (!(cosine > 0.0)) return 0.0;
    return (shininess + 2.0) / (2.0 * kPi) * std::pow(cosine, shininess);
}

}  // namespace csgrt
