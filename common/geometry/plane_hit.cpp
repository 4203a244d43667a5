#include "common/geometry/plane_hit.h"

#include <cmath>

#include "common/geometry/rounding_error.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_plane_z0(const Ray& ray, double t_max) {
  if (ray.d.z == 0.0) return std::nullopt;
  // Decided by signs alone (o_z and d_z of opposite signs), so a ray spawned
  // off the plane to one side never finds the plane behind it.
  const double t = -ray.o.z / ray.d.z;
  if (!(t > 0.0) || !(t < t_max)) return std::nullopt;
  ShapeHit hit;
  hit.t = t;
  hit.p = {ray.o.x + t * ray.d.x, ray.o.y + t * ray.d.y, 0.0};
  hit.p_error = {rounding_gamma(3) * (std::abs(ray.o.x) + std::abs(t * ray.d.x)),
                 rounding_gamma(3) * (std::abs(ray.o.y) + std::abs(t * ray.d.y)), 0.0};
  hit.n = {0.0, 0.0, 1.0};
  return hit;
}

}  // namespace skyfarm
