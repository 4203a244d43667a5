#include "common/accel/ray_triangle.h"

#include <glm/geometric.hpp>

namespace skyfarm::accel {

std::optional<TriangleHit> intersect_triangle(const glm::dvec3& origin, const glm::dvec3& dir,
                                              const glm::dvec3& p0, const glm::dvec3& p1,
                                              const glm::dvec3& p2) {
  const glm::dvec3 e1 = p1 - p0;
  const glm::dvec3 e2 = p2 - p0;
  const glm::dvec3 p = glm::cross(dir, e2);
  const double det = glm::dot(e1, p);
  // Exactly parallel (or a degenerate triangle): no single crossing point.
  if (det == 0.0 || !(det == det)) return std::nullopt;
  const double inv_det = 1.0 / det;
  const glm::dvec3 s = origin - p0;
  const double u = glm::dot(s, p) * inv_det;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(dir, q) * inv_det;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double t = glm::dot(e2, q) * inv_det;
  return TriangleHit{t, u, v};
}

}  // namespace skyfarm::accel
