// One ray's march through the atmosphere, split into the part that depends
// only on the ray (prepare: steps, altitudes, coefficients, transmittance
// along the ray) and the part that depends on the sun (add_inscattering,
// add_ground: cheap, evaluated for many sun geometries per prepared ray).
// The sky-view, aerial-perspective and ground-irradiance tables and the
// per-ray reference march all use it.
//
// Radiance here is per unit of solar irradiance at the top of the
// atmosphere (1/sr); callers multiply by E_sun per bin.  For a ray leaving
// x_0 (radius r_0) in direction v, with the sun in direction s:
//   L = sum_k T(x_0, x_k-) int_k exp(-sigma_t s) ds  J(x_k)          (segment_integral.h)
//     + [ends on the ground] T(x_0, x_g) rho/pi (T_sun(x_g) max(0, mu_g) + I(mu_g))
//   J(x) = T_sun(x) sum_c sigma_s,c(x) p_c(nu) + sigma_s(x) Psi_ms(h, mu_s(x))
// with nu = v . s (the cosine between the sunlight's propagation -s and the
// scattered light's -v), T_sun the transmittance LUT (0 when the planet
// hides the sun), Psi_ms Hillaire's multiple-scattering LUT, I the ground
// irradiance LUT (sky light on the ground per unit E_sun).  Along the ray,
// x_t . s = r_0 mu_s0 + t nu, so the sun's zenith cosine at x_t is
//   mu_s(t) = (r_0 mu_s0 + t nu) / r_t,
// which depends on the sun only through mu_s0 (at x_0) and nu.
//
// Precision and speed: geometry, positions in the tables and T(x_0, x_k)
// are double; the per-step weights, the phase values and the sums over a
// call's steps are single precision, like the transmittance and multiple-
// scattering tables (bilinear.h), and are added to the caller's doubles once
// per call.  Views go in tiles of 32 (their data stay in the L1 cache), and
// when a tile's views fall on fewer table nodes than there are views, both
// tables are interpolated to the step's radius once and each view along
// mu_s only (add_step).
#pragma once
#include <span>
#include <vector>

#include "common/lut/medium_table.h"
#include "common/lut/multiple_scattering_lut.h"
#include "common/lut/simd_clones.h"
#include "common/lut/transmittance_lut.h"

namespace skyfarm {

class GroundIrradianceLut;
class MultipleScatteringBands;

class ScatteringMarch {
 public:
  // multiple_scattering and ground_irradiance may be null (left out).
  ScatteringMarch(const MediumTable& medium, const TransmittanceLut& transmittance,
                  const MultipleScatteringLut* multiple_scattering, const GroundIrradianceLut* ground_irradiance);

  // A ray from radius r0 with zenith cosine mu over [0, t_end], steps placed
  // by lut::place_steps; ends_on_ground adds the ground term at t_end.
  void prepare(double r0, double mu, double t_end, bool ends_on_ground, int steps);
  // The same with explicit step boundaries 0 = t_0 <= t_1 <= ... (one
  // midpoint sample per interval; the aerial-perspective slices).
  void prepare_boundaries(double r0, double mu, std::span<const double> boundaries, bool ends_on_ground);

  int steps() const { return steps_; }
  // Transmittance from x_0 to the start of step k, per bin (k = steps(): the end).
  const double* T_before(int k) const { return T_before_.data() + static_cast<std::size_t>(k) * bins_; }

  // L[b] += in-scattered radiance of steps [k0, k1) per unit E_sun, for a sun
  // at zenith cosine mu_s0 seen from x_0 and nu = v . s; phase[c * bins + b]
  // = p_c,b(nu) (MediumTable::phase or phase_exact) in single precision, as
  // the tables it multiplies (bilinear.h).
  void add_inscattering(const float* phase, double nu, double mu_s0, int k0, int k1, double* L) const {
    add_inscattering(1, &nu, phase, mu_s0, k0, k1, L);
  }
  // The same for n views that share this ray's altitude profile but not its
  // azimuth (a table row's columns): nu[i], phase + i * scatterers * bins,
  // L + i * bins.  The look-up positions of all n views are computed in one
  // vectorisable pass per step.
  void add_inscattering(int n, const double* nu, const float* phase, double mu_s0, int k0, int k1, double* L) const;
  // The same with a sun per view: mu_s0[i] (the ground-irradiance table's
  // suns, one per view).
  void add_inscattering(int n, const double* nu, const double* mu_s0, const float* phase, int k0, int k1,
                        double* L) const;
  // L[b] += the ground's reflected radiance times T(x_0, x_g), if the ray ends on it.
  void add_ground(double nu, double mu_s0, double* L) const;
  // L[b] += the second order's direction-dependent part along the ray
  // (multiple_scattering_bands.h), per unit E_sun: at each step x_k the
  // view and the sun in x_k's own frame (mu_v(t) = (r_0 mu + t) / r_t, and
  // x_v = (nu - mu_v mu_s) / sin_s, the view's component towards the sun's
  // azimuth), the bands' coefficients there, weighted by the step's
  // per-scatterer weights.
  void add_bands(const MultipleScatteringBands& bands, double nu, double mu_s0, double* L) const;

 private:
  void prepare_steps(double r0, double mu, bool ends_on_ground);
  void add_step(std::size_t k, std::size_t n, const double* nu, const double* mu_s0, const float* phase,
                float* L) const;

  const MediumTable& medium_;
  const TransmittanceLut& transmittance_;
  const MultipleScatteringLut* ms_;
  const GroundIrradianceLut* gi_;
  int bins_, scatterers_, steps_ = 0;
  bool ends_on_ground_ = false;
  double r0_ = 0.0, mu_ = 0.0, t_end_ = 0.0;
  std::vector<double> t_mid_, dt_;
  // Per step: weights T(x_0, x_k-) int_k exp(-sigma_t s) ds sigma_s,c ([k][c][b])
  // and the same with the total sigma_s ([k][b]); T before each step ([k][b]).
  std::vector<float> w_c_, w_ms_;  // single precision, as the tables they weight (bilinear.h)
  std::vector<double> T_before_;
  std::vector<TransmittanceLut::RadiusCoord> radius_;
  std::vector<MultipleScatteringLut::AltitudeCoord> ms_altitude_;
  std::vector<double> c_mu_, c_nu_;      // mu_s(t_k) = c_mu mu_s0 + c_nu nu
  std::vector<double> s_t_, s_s_, s_c_;  // scratch per step
  // Scratch of the look-ups (a ScatteringMarch is used by one thread at a time).
  mutable std::vector<double> tmp_, u_T_, u_ms_, mu0_;
  mutable std::vector<float> w_phase_, L_f_, rows_T_, rows_M_, frac_T_, frac_ms_;
  mutable std::vector<int> node_T_, node_ms_;
  mutable std::vector<float> band_coefficients_;
};

}  // namespace skyfarm
