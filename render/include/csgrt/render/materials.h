#pragma once

#include <optional>

#include "csgrt/core/math.h"

namespace csgrt {

/// The optics of csgrt's materials (docs/rendering.md, "Materials"), after "Ray Tracing from
/// the Ground Up" (Suffern, 2007), chapters 24 (mirror reflection) and 27 (transparency), and
/// pbrt (Pharr, Jakob and Humphreys, 4th ed., 9.3 and 9.5). Every vector is in world space;
/// directions are unit length.

/// The mirror direction of `direction` about the unit `normal` (either side):
/// direction - 2 (direction . normal) normal.
Vector3 reflect(const Vector3& direction, const Normal3& normal);

/// The direction a ray along `direction` takes through an interface with unit `normal` on the
/// side it comes from (normal . direction < 0), `eta` = n_incident / n_transmitted, by Snell's
/// law; nothing when sin(theta_t) = eta sin(theta_i) > 1 (total internal reflection).
std::optional<Vector3> refract(const Vector3& direction, const Normal3& normal, double eta);

/// Fresnel reflectance of unpolarised light at a dielectric interface, the mean of the s and p
/// reflectances, for the cosine of the angle of incidence (clamped to [0, 1]) and the indices
/// of refraction on both sides; 1 under total internal reflection. At normal incidence it is
/// ((n_t - n_i) / (n_t + n_i))^2; at grazing incidence 1.
double fresnel_dielectric(double cos_incident, double eta_incident, double eta_transmitted);

/// The normalised Phong specular BRDF value (Lafortune and Willems, "Using the Modified Phong
/// Reflectance Model for Physically Based Rendering", 1994): (n + 2) / (2 pi) cos^n(alpha),
/// alpha the angle between `to_light` and the mirror direction of `to_viewer` about `normal`
/// (all unit, `normal` on the viewer's side); 0 when cos(alpha) <= 0. Times a specular colour
/// ks, with albedo + ks <= 1 per channel, it reflects no more than it receives.
double phong_lobe(const Vector3& to_light, const Vector3& to_viewer, const Normal3& normal,
                  double shininess);

}  // namespace csgrt
