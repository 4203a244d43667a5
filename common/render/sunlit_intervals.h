// The parts of a ray segment the sun reaches: the segment minus the planet's
// shadow, which for a distant sun is the half-cylinder of radius R behind the
// planet, { x : x.s < 0 and |x - (x.s) s| < R } (s towards the sun; the
// atmosphere's own extinction is not a shadow here).  Along the ray the
// cylinder is a quadratic inequality and "behind" a linear one, so the shadow
// is one interval of t and the lit part at most two, in closed form.
//
//   ray, t0, t1   the segment [t0, t1] of the ray
//   s             unit vector towards the sun
//   R             planet radius (m)
#pragma once
#include <array>
#include <utility>

#include <glm/vec3.hpp>

#include "common/geometry/ray.h"

namespace skyfarm {

struct SunlitIntervals {
  std::array<std::pair<double, double>, 2> lit{};  // in order along the ray
  int count = 0;
  bool shadowed = false;  // some of [t0, t1] is in the shadow
};

SunlitIntervals sunlit_intervals(const Ray& ray, double t0, double t1, const glm::dvec3& s, double R);

}  // namespace skyfarm
