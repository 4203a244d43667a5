#include "common/geometry/equal_area.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "common/core/constants.h"

namespace skyfarm {

// Square -> sphere (Clarberg 2008, section 3).  With u, v in [-1, 1] and
// the signed distance from the equator's diamond s_d = 1 - (|u| + |v|), the
// "radius" r = 1 - |s_d| runs from 0 at the poles to 1 on the equator, the
// height is z = sign(s_d) (1 - r^2), and the azimuth inside the quadrant is
// phi = pi/4 ((|v| - |u|) / r + 1), linear along the diamond's edges.  Why
// the areas are kept: the diamond |u| + |v| <= r covers 2 r^2 of the
// square's 4, the cap z >= 1 - r^2 covers 2 pi r^2 of the sphere's 4 pi (the
// same fraction), and phi splits both alike.  The horizontal length of the
// unit vector is sqrt(1 - z^2) = r sqrt(2 - r^2).
glm::dvec3 equal_area_square_to_sphere(const glm::dvec2& p) {
  const double u = 2.0 * std::clamp(p.x, 0.0, 1.0) - 1.0;
  const double v = 2.0 * std::clamp(p.y, 0.0, 1.0) - 1.0;
  const double au = std::abs(u), av = std::abs(v);
  const double signed_distance = 1.0 - (au + av);
  const double r = 1.0 - std::abs(signed_distance);
  const double phi = (r == 0.0 ? 1.0 : (av - au) / r + 1.0) * (kPi / 4.0);
  const double z = std::copysign(1.0 - r * r, signed_distance);
  const double horizontal = r * std::sqrt(std::max(0.0, 2.0 - r * r));
  return {std::copysign(std::cos(phi), u) * horizontal, std::copysign(std::sin(phi), v) * horizontal, z};
}

// Sphere -> square, the inverse of the above: r = sqrt(1 - |z|), the
// quadrant's azimuth as a fraction t = phi / (pi/2), then |v| = t r and
// |u| = r - |v| in the upper hemisphere; the lower one is the upper one's
// triangle folded out over the diamond's edge (|u| -> 1 - |v|, |v| -> 1 - |u|).
glm::dvec2 equal_area_sphere_to_square(const glm::dvec3& direction) {
  const glm::dvec3 d = glm::normalize(direction);
  const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  const double r = std::sqrt(std::max(0.0, 1.0 - az));
  const double t = (ax == 0.0 && ay == 0.0) ? 0.0 : std::atan2(ay, ax) * (2.0 / kPi);
  double v = t * r;
  double u = r - v;
  if (d.z < 0.0) {
    const double folded_u = 1.0 - v;
    v = 1.0 - u;
    u = folded_u;
  }
  u = std::copysign(u, d.x);
  v = std::copysign(v, d.y);
  return {0.5 * (u + 1.0), 0.5 * (v + 1.0)};
}

double equal_area_pixel_solid_angle(int n) { return 4.0 * kPi / (double(n) * double(n)); }

}  // namespace skyfarm
