// Bounds on floating-point rounding error in double precision, for the
// shapes' hit points and the spawn offsets that keep a new ray off the
// surface it leaves (Pharr, Jakob & Humphreys, Physically Based Rendering,
// 3rd ed., §3.9).
//
//   unit roundoff  u = 2^-53: |fl(a op b) - (a op b)| <= u |a op b|
//   gamma(n)       n u / (1 - n u): bound on the relative error of n
//                  successive roundings, (1 + u)^n - 1 <= gamma(n)
//   next_up/down   the neighbouring double towards +inf / -inf
#pragma once
#include <cmath>
#include <limits>

namespace skyfarm {

inline constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() * 0.5;

inline constexpr double rounding_gamma(int n) { return (n * kUnitRoundoff) / (1.0 - n * kUnitRoundoff); }

inline double next_up(double x) { return std::nextafter(x, std::numeric_limits<double>::infinity()); }
inline double next_down(double x) { return std::nextafter(x, -std::numeric_limits<double>::infinity()); }

}  // namespace skyfarm
