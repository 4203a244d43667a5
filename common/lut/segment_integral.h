// Closed forms for one step of a ray march through a medium that is taken as
// homogeneous over the step (extinction sigma_t, m^-1, over a length dt, m).
//
//   T(sigma_t, dt)                  = exp(-sigma_t dt)                transmittance
//   in_scattering_integral(s_t, dt) = int_0^dt exp(-sigma_t s) ds     m
//                                   = -expm1(-sigma_t dt) / sigma_t
//                                   = dt * (1 - exp(-x)) / x,   x = sigma_t dt
//
// A constant source J (radiance per metre) over the step then adds
// J * in_scattering_integral behind the transmittance accumulated so far
// (Hillaire 2020, §5 "energy-conserving" per-step integration; Hillaire,
// "Physically based and unified volumetric rendering in Frostbite", 2015,
// slide 28).
//
// Numerics: the textbook
// (1 - exp(-sigma_t dt)) / sigma_t is 0/0 for sigma_t = 0 (an empty layer,
// or a coefficient that underflowed) and loses all digits to cancellation
// for tiny x.  Here x = sigma_t dt is formed first; for x < 1e-4 the Taylor
// series 1 - x/2 + x^2/6 (next term x^3/24 < 4.2e-14 relative) replaces the
// quotient, otherwise -expm1(-x)/x, which is exact to rounding for all x > 0
// and tends to 1/x (no overflow, no NaN) for large x (core/math.h).  The
// results are never NaN for finite inputs (dt = infinity is the caller's to
// avoid: 0 * inf); negative sigma_t or dt are clamped to 0 (a table
// interpolated below zero by round-off).
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include "common/core/math.h"
#include "common/lut/vector_math.h"

namespace skyfarm::lut {

// phi(x) = (1 - exp(-x)) / x with phi(0) = 1: core/math.h one_minus_exp_over_x
// (series below 1e-4), evaluated at max(0, x).
inline double phi(double x) { return one_minus_exp_over_x(std::max(0.0, x)); }

// Transmittance of a homogeneous step: exp(-sigma_t dt) (Beer-Lambert).
inline double T(double sigma_t, double dt) { return std::exp(-std::max(0.0, sigma_t) * std::max(0.0, dt)); }

// int_0^dt exp(-sigma_t s) ds = dt phi(sigma_t dt): tends to dt as sigma_t -> 0
// and to 1/sigma_t as sigma_t dt -> infinity.
inline double in_scattering_integral(double sigma_t, double dt) {
  const double d = std::max(0.0, dt);
  return d * phi(std::max(0.0, sigma_t) * d);
}

// Both from a single exponential (the hot loops call this): returns the
// transmittance and stores the integral in *integral.  For x >= 1e-4 the
// difference 1 - exp(-x) loses at most eps/x ~ 2e-12 relative to
// cancellation, far below what the tables resolve.  Branch-free, with
// lut::exp_inline, so that loops over bins vectorise: both branches are
// evaluated (the quotient's denominator kept > 0) and one is selected.
inline double T_and_in_scattering_integral(double sigma_t, double dt, double* integral) {
  const double s = std::max(0.0, sigma_t), d = std::max(0.0, dt);
  const double x = s * d;
  const double t = exp_inline(-x);
  const double series = d * (1.0 - x * (0.5 - x * (1.0 / 6.0)));
  const double quotient = (1.0 - t) / std::max(s, std::numeric_limits<double>::min());
  *integral = x < 1e-4 ? series : quotient;
  return t;
}

// The same in single precision, for weights stored as floats (the
// multiple-scattering table's): 16 per AVX-512 instruction, a float
// division instead of a double one.  In floats 1 - exp(-x) loses eps_f/x
// (6e-8/x) relative, so the series (to x^4: next term x^5/720 < 3.4e-11)
// serves up to x = 0.03, where the quotient's loss is 2e-6 at most.
inline float T_and_in_scattering_integral_f(float sigma_t, float dt, float* integral) {
  const float s = std::max(0.0f, sigma_t), d = std::max(0.0f, dt);
  const float x = s * d;
  const float t = exp_inline_f(-x);
  const float series = d * (1.0f - x * (0.5f - x * (1.0f / 6.0f - x * (1.0f / 24.0f - x * (1.0f / 120.0f)))));
  const float quotient = (1.0f - t) / std::max(s, std::numeric_limits<float>::min());
  *integral = x < 0.03f ? series : quotient;
  return t;
}

}  // namespace skyfarm::lut
