// Small numerically safe helpers (Bruneton 2017, functions.glsl "clamp" helpers).
#pragma once
#include <algorithm>
#include <cmath>

namespace skyfarm {

inline double safe_sqrt(double x) { return std::sqrt(std::max(0.0, x)); }
inline double clamp_cos(double mu) { return std::clamp(mu, -1.0, 1.0); }
inline double sqr(double x) { return x * x; }
inline double lerp(double t, double a, double b) { return a + t * (b - a); }

// (1 - exp(-x)) / x, accurate for x -> 0 (series) and safe for x = 0:
// the segment integral of a constant source through a homogeneous slab.
inline double one_minus_exp_over_x(double x) {
  if (std::abs(x) < 1e-4) return 1.0 - x * (0.5 - x / 6.0);
  return -std::expm1(-x) / x;
}

}  // namespace skyfarm
