// The direction-dependent part of the second scattering order, as a few
// spherical-harmonic bands: what Hillaire's (2020) isotropic multiple-
// scattering term leaves out.
//
// Hillaire's Psi_ms (multiple_scattering_lut.h) gives every point one
// radiance for all directions: the light of the orders >= 2 is scattered
// isotropically.  Under a low sun most of the light arriving at a point is
// the aerosols' forward peak around the sun and the bright horizon band;
// scattered again with the true (forward-peaked) phase functions it stays
// near the sun and the horizon, which the isotropic term spreads over the
// whole sky (the LUT was -10 to -28 % low near the horizon and up to +24 %
// high in the anti-solar sky, against the path tracer).  This table keeps
// the bands l = 0 .. max_band of the first-order light L1(x, w) arriving at a
// point x from direction w,
//   a_lm(h, mu_s) = int_4pi L1(x, w) Y_lm(w) dw       (mirror_harmonics.h)
// in the point's frame (z up, x towards the sun's azimuth), per unit solar
// irradiance, where L1 is the single-scattered light (true phase functions,
// the sun's visibility from the transmittance table) plus the ground's
// Lambertian reflection of the sun and of the sky (ground irradiance table:
// the sky-lit ground).  By Funk-Hecke, the light scattered at x into the
// direction v then gains
//   J(x, v) = sum_c sigma_s,c(x) sum_l g_l,c sum_m a_lm Y_lm(v)
// over Hillaire's isotropic sigma_s Psi_ms; g_l,c are the Legendre moments
// of scatterer c's phase function (phase_moments below; g_0 = 1, g_1 is the
// asymmetry g).  The bands l >= 1 add no energy on average over directions
// (their harmonics have mean 0).  Band 0 is the mean, which Psi_ms already
// carries with an isotropic first scattering and only the direct sun on the
// ground: a_00 keeps the difference, sqrt(4 pi) (mean L1 - mean L1_iso),
// divided by Hillaire's 1 - f_ms (from the same directions) so that the
// higher orders carry it as they carry his.
//
// Quadrature: per node, `rings` zenith rings crowded at the horizon
// (mirrored_rings.h) times `azimuths` azimuths over [0, pi] (the mirror
// half), each marched with `steps` steps (lut::place_steps).  The aerosols'
// forward peak is too narrow for so few directions, so the single-scattering
// part goes through a control variate: with F_c(w) = int T sigma_s,c T_sun
// along w (smooth in w) and A_c = F_c(s) marched towards the sun,
//   int p_c(w . s) F_c(w) Y_lm(w) dw = A_c g_l,c Y_lm(s)             (exact)
//                                    + int p_c(w . s) (F_c(w) - A_c) Y_lm(w) dw,
// and only the second, small near the peak, is left to the quadrature.
//
// Parameters (LutResolution::bands_*)
//   max_band         highest band (default 2; 0 turns the table off:
//                    Hillaire's term alone)
//   mu_s_samples     sun zenith cosine nodes (default 24), x in [-1, 1]
//                    equally spaced with mu_s = x (0.3 + 0.7 |x|): denser
//                    near the horizon, where the bands change fastest
//   altitude_samples altitude nodes (default 8), h = top x^2 (denser low
//                    down, where the aerosols are)
//   rings, azimuths  directions per node (default 12 x 6)
//   steps            march steps per direction (default 8)
// The defaults are the cheapest of those tried that keep the daytime error
// against the path tracer (docs/experiments/2026-12-07-anisotropic-
// multiple-scattering.md); twilight wants the 24 mu_s nodes.
//
// Layout: [altitude][mu_s][harmonic][bin], single precision.
#pragma once
#include <cstddef>
#include <vector>

#include "common/core/huge_page_allocator.h"
#include "common/lut/ground_irradiance_lut.h"
#include "common/lut/medium_table.h"
#include "common/lut/mirror_harmonics.h"
#include "common/lut/transmittance_lut.h"

namespace skyfarm {

// g_l of every scatterer's phase function per bin, l = 0 .. max_band:
// out[(l * scatterers + c) * bins + b] = 2 pi int p_c,b(mu) P_l(mu) dmu, by
// the midpoint rule on 4096 nodes of theta = pi x^2 (dense in the forward
// peak) with the exact phase functions (MediumTable::phase_exact).
std::vector<double> phase_moments(const MediumTable& medium, int max_band);

class MultipleScatteringBands {
 public:
  static MultipleScatteringBands build(const MediumTable& medium, const TransmittanceLut& transmittance,
                                       const GroundIrradianceLut& ground, int max_band = 2, int mu_s_samples = 24,
                                       int altitude_samples = 8, int rings = 12, int azimuths = 6, int steps = 8);

  int max_band() const { return max_band_; }
  // Harmonics stored per node and bin: l = 0 .. max_band, all m >= 0
  // (0 when the table is off).
  int harmonics() const { return harmonics_; }
  int bins() const { return bins_; }
  // g_l,c per bin (phase_moments).
  double moment(int l, int c, int b) const {
    return moments_[(static_cast<std::size_t>(l) * scatterers_ + static_cast<std::size_t>(c)) * bins_ +
                    static_cast<std::size_t>(b)];
  }

  // a_lm per bin at (altitude, mu_s), bilinear between the nodes:
  // out[mirror_harmonic_index(l, m) * bins + b].
  void coefficients(double altitude_m, double mu_s, float* out) const;

  // The bands' source for a view v at a point: acc[b] += sum_c w_c[c * bins + b]
  // sum_l g_l,c sum_m a_lm Y_lm(v), with v given in the point's frame
  // by its zenith cosine mu_v and x_v = v . (sun's azimuth direction);
  // coefficients as coefficients() returns them.  w_c: per-scatterer weights
  // (e.g. T int exp(-sigma_t s) ds sigma_s,c of a march step).
  void add_source(const float* coefficients, double mu_v, double x_v, const float* w_c, double* acc) const;

  std::size_t memory_bytes() const { return table_memory_bytes(values_) + moments_.size() * sizeof(double); }

 private:
  double mu_s_position(double mu_s) const;

  int max_band_ = 0, harmonics_ = 0, bins_ = 0, scatterers_ = 0, n_mu_s_ = 0, n_h_ = 0;
  double top_altitude_ = 0.0;
  std::vector<double> moments_;
  TableVector<float> values_;
};

}  // namespace skyfarm
