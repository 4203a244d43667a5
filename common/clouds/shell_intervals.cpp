#include "common/clouds/shell_intervals.h"

#include <algorithm>

#include "common/geometry/sphere_intersection.h"

namespace skyfarm {

// Inside the outer ball on [a, b] (its two roots); inside the inner ball on
// [c, d]; the shell is [a, b] minus (c, d): [a, c] and [d, b] when the line
// meets the inner sphere, else [a, b].
ShellIntervals shell_intervals(const Ray& ray, double r_bottom, double r_top, double t_begin, double t_end) {
  ShellIntervals out;
  const RadialRay radial = radial_ray(ray);
  const SphereHit outer = intersect_sphere(radial, r_top);
  if (!outer.hit) return out;
  const SphereHit inner = r_bottom > 0.0 ? intersect_sphere(radial, r_bottom) : SphereHit{};
  const auto add = [&](double a, double b) {
    a = std::max(a, t_begin);
    b = std::min(b, t_end);
    if (b > a) {
      out.t0[static_cast<std::size_t>(out.count)] = a;
      out.t1[static_cast<std::size_t>(out.count)] = b;
      ++out.count;
    }
  };
  if (inner.hit) {
    add(outer.t_near, inner.t_near);
    add(inner.t_far, outer.t_far);
  } else {
    add(outer.t_near, outer.t_far);
  }
  return out;
}

}  // namespace skyfarm
