// Real spherical harmonics that are even in y: Y_lm(w) with m >= 0 and the
// cos(m phi) dependence only.  A sky lit by one sun and horizontally uniform
// is mirror-symmetric about the sun's vertical plane (y = 0 in a frame whose
// x axis points to the sun's azimuth), so these are the only harmonics its
// light has; (L + 1)(L + 2)/2 of them up to band L.
//
//   Y_lm(theta, phi) = N_lm P_l^m(cos theta) cos(m phi),
//   N_lm = sqrt((2l + 1)/(4 pi) (l - m)!/(l + m)!) (times sqrt 2 for m > 0),
// orthonormal over the sphere (Sloan 2008, "Stupid Spherical Harmonics
// Tricks", without the Condon-Shortley phase: the sign convention only has
// to match between projection and evaluation).  With w = (x, y, z) a unit
// vector, sin^m(theta) cos(m phi) = Re (x + i y)^m, which depends on y only
// through y^2, and P_l^m = sin^m(theta) Q_l^m(z) with
//   Q_m^m = (2m - 1)!!,  Q_{m+1}^m = (2m + 1) z Q_m^m,
//   Q_l^m = ((2l - 1) z Q_{l-1}^m - (l + m - 1) Q_{l-2}^m) / (l - m).
// Funk-Hecke: for a phase function p(w . v) normalised over the sphere,
//   int p(w . v) Y_lm(w) dw = g_l Y_lm(v),  g_l = 2 pi int_{-1}^{1} p(mu) P_l(mu) dmu,
// which is what lets a table of the harmonics of the light arriving at a
// point give the light it scatters into any direction.
#pragma once
#include <cmath>

#include "common/core/constants.h"

namespace skyfarm::lut {

inline constexpr int kMaxHarmonicBand = 4;

constexpr int mirror_harmonic_count(int max_band) { return (max_band + 1) * (max_band + 2) / 2; }
// Index of (l, m), 0 <= m <= l, in band order.
constexpr int mirror_harmonic_index(int l, int m) { return l * (l + 1) / 2 + m; }

// out[mirror_harmonic_index(l, m)] = Y_lm(w) for l <= max_band (<=
// kMaxHarmonicBand), w = (x, y, z) unit, given z, x and y^2.
inline void mirror_harmonics(int max_band, double z, double x, double y_squared, double* out) {
  // Re and Im of (x + i y)^m, with Im carried as a multiple of y (so that
  // only y^2 appears): (x + i y)^m = c_m + i y d_m.
  double c[kMaxHarmonicBand + 1], d[kMaxHarmonicBand + 1];
  c[0] = 1.0;
  d[0] = 0.0;
  for (int m = 1; m <= max_band; ++m) {
    c[m] = c[m - 1] * x - d[m - 1] * y_squared;
    d[m] = c[m - 1] + d[m - 1] * x;
  }
  double double_factorial = 1.0;  // (2m - 1)!!
  for (int m = 0; m <= max_band; ++m) {
    if (m > 0) double_factorial *= 2 * m - 1;
    double q_prev = 0.0, q = double_factorial;  // Q_{l-1}^m, Q_l^m at l = m
    // (l - m)!/(l + m)! at l = m is 1/(2m)!.
    double ratio = 1.0;
    for (int k = 2; k <= 2 * m; ++k) ratio /= k;
    for (int l = m; l <= max_band; ++l) {
      if (l == m + 1) {
        q_prev = q;
        q = (2 * m + 1) * z * q_prev;
      } else if (l > m + 1) {
        const double next = ((2 * l - 1) * z * q - (l + m - 1) * q_prev) / (l - m);
        q_prev = q;
        q = next;
      }
      if (l > m) ratio *= static_cast<double>(l - m) / static_cast<double>(l + m);
      const double norm = std::sqrt((2 * l + 1) * kInv4Pi * ratio) * (m > 0 ? std::sqrt(2.0) : 1.0);
      out[mirror_harmonic_index(l, m)] = norm * q * c[m];
    }
  }
}

}  // namespace skyfarm::lut
