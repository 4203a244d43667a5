#include "common/geometry/unit_sphere.h"

#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/core/math.h"
#include "common/geometry/rounding_error.h"
#include "common/geometry/sphere_intersection.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_sphere(const Ray& ray, double t_max) {
  const double len = glm::length(ray.d);
  if (!(len > 0.0)) return std::nullopt;
  const SphereHit h = intersect_sphere(Ray{ray.o, ray.d / len}, 1.0);
  if (!h.hit) return std::nullopt;
  // Roots in units of the unit direction; back to the ray's own.
  double t = h.t_near / len;
  if (!(t > 0.0)) t = h.t_far / len;
  if (!(t > 0.0) || !(t < t_max)) return std::nullopt;
  ShapeHit hit;
  hit.t = t;
  glm::dvec3 p = ray.at(t);
  p /= glm::length(p);
  hit.p = p;
  hit.p_error = rounding_gamma(5) * glm::abs(p);
  hit.n = p;
  double phi = std::atan2(p.y, p.x);
  if (phi < 0.0) phi += 2.0 * kPi;
  hit.uv = {phi / (2.0 * kPi), std::atan2(std::sqrt(p.x * p.x + p.y * p.y), p.z) / kPi};
  return hit;
}

AreaSample sample_unit_sphere(const glm::dvec2& u) {
  const double z = 1.0 - 2.0 * u.x;
  const double r = safe_sqrt((1.0 - z) * (1.0 + z));
  const double phi = 2.0 * kPi * u.y;
  AreaSample s;
  s.p = {r * std::cos(phi), r * std::sin(phi), z};
  s.n = s.p;
  s.pdf_area = 1.0 / kUnitSphereArea;
  return s;
}

}  // namespace skyfarm
