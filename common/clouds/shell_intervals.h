// Where a ray runs inside a spherical shell r_bottom <= |p| <= r_top (a cloud
// layer, a slab of the tests): at most two intervals of t, clipped to
// [t_begin, t_end], in increasing t.  The planet's own shadowing is not the
// shell's business: a caller that stops at the ground passes its t_end.
#pragma once
#include <array>

#include "common/geometry/ray.h"

namespace skyfarm {

struct ShellIntervals {
  std::array<double, 2> t0{}, t1{};
  int count = 0;
};

ShellIntervals shell_intervals(const Ray& ray, double r_bottom, double r_top, double t_begin, double t_end);

}  // namespace skyfarm
