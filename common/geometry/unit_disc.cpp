#include "common/geometry/unit_disc.h"

#include <cmath>

#include "common/core/constants.h"
#include "common/geometry/plane_hit.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_disc(const Ray& ray, double t_max) {
  auto hit = intersect_plane_z0(ray, t_max);
  if (!hit) return std::nullopt;
  const double r2 = hit->p.x * hit->p.x + hit->p.y * hit->p.y;
  if (r2 > 1.0) return std::nullopt;
  double phi = std::atan2(hit->p.y, hit->p.x);
  if (phi < 0.0) phi += 2.0 * kPi;
  hit->uv = {std::sqrt(r2), phi / (2.0 * kPi)};
  return hit;
}

AreaSample sample_unit_disc(const glm::dvec2& u) {
  const double a = 2.0 * u.x - 1.0, b = 2.0 * u.y - 1.0;
  AreaSample s;
  s.pdf_area = 1.0 / kUnitDiscArea;
  if (a == 0.0 && b == 0.0) return s;
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (kPi / 4.0) * (b / a);
  } else {
    r = b;
    phi = kPi / 2.0 - (kPi / 4.0) * (a / b);
  }
  s.p = {r * std::cos(phi), r * std::sin(phi), 0.0};
  return s;
}

}  // namespace skyfarm
