#include "common/geometry/spawn.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "common/geometry/rounding_error.h"

namespace skyfarm {

glm::dvec3 offset_ray_origin(const glm::dvec3& p, const glm::dvec3& p_error, const glm::dvec3& n,
                             const glm::dvec3& w) {
  const double d = glm::dot(glm::abs(n), p_error);
  const glm::dvec3 side = glm::dot(w, n) < 0.0 ? -n : n;
  glm::dvec3 po = p + d * side;
  // The addition rounds too: step one ulp further out so the rounding never
  // brings the origin back inside the error box.  Stepping by the normal's
  // signs (not the offset's) also moves a point whose error bound along n is
  // zero (a plane's coordinate set exactly) off the plane.
  for (int i = 0; i < 3; ++i) {
    if (side[i] > 0.0)
      po[i] = next_up(po[i]);
    else if (side[i] < 0.0)
      po[i] = next_down(po[i]);
  }
  return po;
}

Ray spawn_ray(const ShapeHit& hit, const glm::dvec3& w) { return {offset_ray_origin(hit.p, hit.p_error, hit.n, w), w}; }

}  // namespace skyfarm
