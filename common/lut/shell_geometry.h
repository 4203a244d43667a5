// Rays in a spherical shell described by (r, mu): the distance r from the
// planet's centre and the cosine mu of the ray's zenith angle there
// (Bruneton 2017, functions.glsl "Intersections"), and the placement of the
// steps of a ray march along them.
//
// All in double precision: with r ~ 6.4e6 m the squared terms are ~4e13 m^2;
// the discriminants below are formed as r^2 mu^2 - (r - R)(r + R), which
// keeps the small difference r^2 - R^2 exact for rays near the ground.
#pragma once
#include <algorithm>
#include <cmath>

#include "common/core/math.h"

namespace skyfarm::lut {

// Discriminant of |p(t)| = R along the ray: r^2 (mu^2 - 1) + R^2.
inline double discriminant(double r, double mu, double R) { return r * r * mu * mu - (r - R) * (r + R); }

// Distance from (r, mu) to the sphere of radius R_top >= r, outwards:
// d = -r mu + sqrt(r^2 (mu^2 - 1) + R_top^2) (Bruneton DistanceToTopAtmosphereBoundary).
inline double distance_to_top(double r, double mu, double R_top) {
  return std::max(0.0, -r * mu + safe_sqrt(discriminant(r, mu, R_top)));
}

// True when the ray from (r, mu) meets the ground sphere of radius R <= r:
// mu < 0 and r^2 (mu^2 - 1) + R^2 >= 0 (Bruneton RayIntersectsGround).
inline bool ray_hits_ground(double r, double mu, double R) { return mu < 0.0 && discriminant(r, mu, R) >= 0.0; }

// Distance to the ground for a ray that hits it: -r mu - sqrt(...)
// (Bruneton DistanceToBottomAtmosphereBoundary).
inline double distance_to_ground(double r, double mu, double R) {
  return std::max(0.0, -r * mu - safe_sqrt(discriminant(r, mu, R)));
}

// Radius and zenith cosine after a distance t along the ray:
// r_t = sqrt(t^2 + 2 r mu t + r^2), mu_t = (r mu + t) / r_t (law of cosines).
inline double radius_at(double r, double mu, double t) {
  return std::sqrt(std::max(0.0, t * t + 2.0 * r * mu * t + r * r));
}

// Cosine of the zenith angle of the geometric horizon seen from r > R:
// -sqrt(1 - (R/r)^2).
inline double horizon_mu(double r, double R) { return -safe_sqrt((r - R) * (r + R)) / r; }

// Steps of a march over [0, t_end] along the ray from (r, mu): n segments
// [t_k, t_k+1], sampled at their midpoints, with the short steps where the
// air is densest.  The ray is split at its closest approach to the centre,
// t* = -r mu, when that lies inside; on the descending part the steps
// shrink quadratically towards its end, on the ascending part they grow
// quadratically from its start (t_k = L (k/n)^2; Hillaire 2020 places his
// samples the same way from the camera).  Each part gets a share of the
// steps proportional to its length, at least one, when both exist.
//   t_mid[k], dt[k] for k < n; n >= 1.
inline void place_steps(double r, double mu, double t_end, int n, double* t_mid, double* dt) {
  const double t_star = -r * mu;
  auto fill = [&](double a, double b, int count, bool fine_at_end, double* tm, double* d) {
    double prev = a;
    for (int k = 1; k <= count; ++k) {
      const double u = static_cast<double>(k) / count;
      const double w = fine_at_end ? 1.0 - sqr(1.0 - u) : u * u;
      const double next = k == count ? b : a + (b - a) * w;
      tm[k - 1] = 0.5 * (prev + next);
      d[k - 1] = next - prev;
      prev = next;
    }
  };
  if (t_star <= 0.0) return fill(0.0, t_end, n, false, t_mid, dt);
  if (t_star >= t_end || n < 2) return fill(0.0, t_end, n, true, t_mid, dt);
  const int n1 = std::clamp(static_cast<int>(std::lround(n * t_star / t_end)), 1, n - 1);
  fill(0.0, t_star, n1, true, t_mid, dt);
  fill(t_star, t_end, n - n1, false, t_mid + n1, dt + n1);
}

}  // namespace skyfarm::lut
