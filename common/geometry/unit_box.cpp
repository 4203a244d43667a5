#include "common/geometry/unit_box.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/geometry/rounding_error.h"

namespace skyfarm {

std::optional<ShapeHit> intersect_unit_box(const Ray& ray, double t_max) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double t_enter = -kInf, t_exit = kInf;
  int enter_face = -1, exit_face = -1;
  for (int a = 0; a < 3; ++a) {
    if (ray.d[a] == 0.0) {
      // Parallel to this slab: inside it (edges included) or a miss.
      if (std::abs(ray.o[a]) > 0.5) return std::nullopt;
      continue;
    }
    // Planes -0.5 and +0.5; which is entered first depends on d's sign.
    const double t_lo = (-0.5 - ray.o[a]) / ray.d[a];
    const double t_hi = (0.5 - ray.o[a]) / ray.d[a];
    const bool forward = ray.d[a] > 0.0;
    const double t_near = forward ? t_lo : t_hi, t_far = forward ? t_hi : t_lo;
    const int near_face = 2 * a + (forward ? 0 : 1), far_face = 2 * a + (forward ? 1 : 0);
    if (t_near > t_enter) {
      t_enter = t_near;
      enter_face = near_face;
    }
    if (t_far < t_exit) {
      t_exit = t_far;
      exit_face = far_face;
    }
  }
  if (t_enter > t_exit) return std::nullopt;
  double t;
  int face;
  if (t_enter > 0.0 && enter_face >= 0) {
    t = t_enter;
    face = enter_face;
  } else if (t_exit > 0.0 && exit_face >= 0) {
    t = t_exit;
    face = exit_face;
  } else {
    return std::nullopt;
  }
  if (!(t < t_max)) return std::nullopt;
  const int axis = face / 2;
  const double side = (face % 2) ? 0.5 : -0.5;
  ShapeHit hit;
  hit.t = t;
  hit.primitive = static_cast<std::uint32_t>(face);
  for (int a = 0; a < 3; ++a) {
    if (a == axis) {
      hit.p[a] = side;
      hit.p_error[a] = 0.0;
    } else {
      hit.p[a] = std::clamp(ray.o[a] + t * ray.d[a], -0.5, 0.5);
      hit.p_error[a] = rounding_gamma(3) * (std::abs(ray.o[a]) + std::abs(t * ray.d[a]));
    }
  }
  hit.n = {0.0, 0.0, 0.0};
  hit.n[axis] = side > 0.0 ? 1.0 : -1.0;
  const int u_axis = axis == 0 ? 1 : 0, v_axis = axis == 2 ? 1 : 2;
  hit.uv = {hit.p[u_axis] + 0.5, hit.p[v_axis] + 0.5};
  return hit;
}

}  // namespace skyfarm
