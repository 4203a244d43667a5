#include "common/render/sunlit_intervals.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace skyfarm {

SunlitIntervals sunlit_intervals(const Ray& ray, double t0, double t1, const glm::dvec3& s, double R) {
  // Inside the cylinder: perp^2(t) = A t^2 + 2 B t + C' < R^2, C' = |o|^2 - (o.s)^2.
  const double os = glm::dot(ray.o, s), ds = glm::dot(ray.d, s);
  const double A = 1.0 - ds * ds, B = glm::dot(ray.o, ray.d) - os * ds;
  const double C = (glm::dot(ray.o, ray.o) - os * os) - R * R;
  double c0 = 1.0, c1 = 0.0;  // inside-cylinder interval (empty if c0 > c1)
  if (A > 1e-12) {
    const double disc = B * B - A * C;
    if (disc > 0.0) {
      const double root = std::sqrt(disc);
      c0 = (-B - root) / A;
      c1 = (-B + root) / A;
    }
  } else if (C < 0.0) {
    c0 = -1e300;
    c1 = 1e300;
  }
  // Behind the planet: x.s < 0, i.e. os + t ds < 0.
  double h0 = -1e300, h1 = 1e300;
  if (ds > 0.0) {
    h1 = -os / ds;
  } else if (ds < 0.0) {
    h0 = -os / ds;
  } else if (os >= 0.0) {  // never behind the planet: an empty half-space
    h0 = 1.0;
    h1 = 0.0;
  }
  const double shadow0 = std::max(c0, h0), shadow1 = std::min(c1, h1);
  SunlitIntervals out;
  if (!(shadow0 < shadow1) || shadow1 <= t0 || shadow0 >= t1) {
    out.lit[out.count++] = {t0, t1};
    return out;
  }
  out.shadowed = true;
  if (shadow0 > t0) out.lit[out.count++] = {t0, shadow0};
  if (shadow1 < t1) out.lit[out.count++] = {shadow1, t1};
  return out;
}

}  // namespace skyfarm
