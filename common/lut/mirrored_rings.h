// Rings of zenith cosine over the sphere, crowded towards the horizon, for
// the multiple-scattering tables' integrals over directions.
//
// `rings` zenith cosines, each carrying the
// mirror pair of azimuths (phi_i, -phi_i) about the sun's vertical plane.
// Both directions of a pair see the same sun (x_t . s depends on cos phi
// only), so one is evaluated for both.  On each side of the horizon mu_h the
// rings are the midpoints of v in [0, 1] with mu = mu_h +- (range) v^2, so
// that they crowd towards the horizon, where the scattered light changes
// fastest (the grazing rays' long paths); sides get rings in proportion to
// their solid angle.  Weights (dmu dphi / 4 pi) sum to 1.  phi_i steps by the
// golden angle, as in a spherical Fibonacci set.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "common/core/constants.h"

namespace skyfarm::lut {

inline constexpr double kGoldenRatio = 1.6180339887498949;  // (1 + sqrt 5) / 2

struct Rings {
  std::vector<double> mu, weight, cos_phi;
};

inline Rings mirrored_rings(int rings, double mu_h) {
  Rings out;
  const int n_ground = std::clamp(static_cast<int>(std::lround(0.5 * rings * (1.0 + mu_h))), 1, rings - 1);
  const int n_sky = rings - n_ground;
  for (int i = 0; i < rings; ++i) {
    const bool sky = i < n_sky;
    const int n = sky ? n_sky : n_ground;
    const double range = sky ? 1.0 - mu_h : 1.0 + mu_h;
    const double v = sky ? 1.0 - (i + 0.5) / n_sky : (i - n_sky + 0.5) / n_ground;
    out.mu.push_back(sky ? mu_h + range * v * v : mu_h - range * v * v);
    out.weight.push_back(0.5 * range * 2.0 * v / n);
    out.cos_phi.push_back(std::cos(2.0 * kPi * i / kGoldenRatio));
  }
  return out;
}
}  // namespace skyfarm::lut
