// Small direction helpers shared by the BSDFs: mirror reflection about a
// normal, an orthonormal frame around a direction, and cosine-weighted
// sampling of the hemisphere around any axis.
#pragma once

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace skyfarm::material {

inline constexpr double kBsdfPi = 3.14159265358979323846;

// The mirror image of w (pointing away) about the normal m: 2 (w.m) m - w.
inline glm::dvec3 reflect_about(const glm::dvec3& w, const glm::dvec3& m) {
  return 2.0 * glm::dot(w, m) * m - w;
}

// A direction drawn with density max(0, w . axis) / pi (Malley's method:
// uniform on the unit disk, lifted), in the frame of the unit vector axis.
// The frame is Duff et al. 2017, "Building an orthonormal basis, revisited".
inline glm::dvec3 sample_cosine_around(const glm::dvec3& axis, const glm::dvec2& u) {
  const double r = std::sqrt(u.x);
  const double phi = 2.0 * kBsdfPi * u.y;
  const double x = r * std::cos(phi);
  const double y = r * std::sin(phi);
  const double z = std::sqrt(std::max(0.0, 1.0 - u.x));
  const double sign = std::copysign(1.0, axis.z);
  const double a = -1.0 / (sign + axis.z);
  const double b = axis.x * axis.y * a;
  const glm::dvec3 t(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
  const glm::dvec3 s(b, sign + axis.y * axis.y * a, -axis.y);
  return glm::normalize(x * t + y * s + z * axis);
}

}  // namespace skyfarm::material
