#include "common/geometry/unit_rectangle.h"

#include <cmath>

#include "common/geometry/plane_hit.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_rectangle(const Ray& ray, double t_max) {
  auto hit = intersect_plane_z0(ray, t_max);
  if (!hit || std::abs(hit->p.x) > 0.5 || std::abs(hit->p.y) > 0.5) return std::nullopt;
  hit->uv = {hit->p.x + 0.5, hit->p.y + 0.5};
  return hit;
}

AreaSample sample_unit_rectangle(const glm::dvec2& u) {
  AreaSample s;
  s.p = {u.x - 0.5, u.y - 0.5, 0.0};
  s.pdf_area = 1.0 / kUnitRectangleArea;
  return s;
}

}  // namespace skyfarm
