// The atmosphere's coefficients per spectral bin, tabulated once so that the
// LUT builders never call the constituents (density profiles, cross-
// sections, phase functions) in their inner loops.
//
// Parameters
//   atmosphere         planet radius, shell top, constituents, ground
//   grid               the spectral bins (coefficients at the bin centres)
//   altitude_samples   nodes equally spaced on [0, top], >= 2 (default 2048:
//                      ~49 m apart for a 100 km shell).  The profiles are
//                      interpolated linearly between them, which over-
//                      estimates an exponential of scale height H by
//                      (dh/H)^2/12 on average: 1.4e-4 for the 1.2 km aerosol
//                      layer at 49 m (5.6e-4 at 1024 nodes, enough to cost
//                      the transmittance LUT its 0.5 % target on long rays)
//   phase_samples      nodes of the tabulated phase functions, >= 2 (default
//                      512), equally spaced in x = sin(theta/2) =
//                      sqrt((1 - nu)/2), which puts them densest in the
//                      forward peak (spacing ~0.004 rad at theta = 0: fine for
//                      Henyey-Greenstein g <~ 0.95)
//
// Per altitude node and bin: sigma_t and sigma_s (totals) and sigma_s of each
// scattering constituent ("scatterer" c; constituents that only absorb are
// folded into sigma_t).  Per scatterer and bin: its PhaseFunction evaluated at
// the bin centre, and that function tabulated on the nu grid.  The single-
// scattering source is sum_c sigma_s,c(h) p_c(nu), nu the cosine between the
// sunlight's propagation direction and the scattered propagation direction.
// The ground's albedo is taken at the bin centres.
//
// Layout: row-major [node][bin] (and [node][c][bin]) so that all bins of one
// altitude are contiguous and the per-bin loops vectorise.
//
// Extinction terms: sigma_t(h, b) = sum_k rho_k(h) kappa_k[b], exactly (to
// rounding), because every constituent's coefficients are its density times
// a spectrum (constituent.h), except ozone's, whose cross-section is linear
// between temperature columns (ozone.h temperature_bracket): each column is
// one term, with the density times the column's weight at that altitude as
// its profile.  The Earth preset has 7 terms (air, aerosols, 5 ozone
// columns) for any number of bins; the transmittance quadrature sums the
// profiles along a ray and expands to the bins once (transmittance_lut.cpp).
// Profiles are stored [node][k], padded with zero terms to a multiple of 8.
#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

#include "common/core/huge_page_allocator.h"
#include "common/atmosphere/atmosphere.h"
#include "common/lut/spectral_grid.h"

namespace skyfarm {

class MediumTable {
 public:
  static MediumTable build(const Atmosphere& atmosphere, const SpectralGrid& grid, int altitude_samples = 2048,
                           int phase_samples = 512);

  int bins() const { return bins_; }
  int scatterers() const { return scatterers_; }
  double planet_radius_m() const { return R_; }
  double top_radius_m() const { return R_top_; }
  double top_altitude_m() const { return R_top_ - R_; }

  // Linear interpolation between altitude nodes i and i + 1 with weight f
  // (altitude clamped to [0, top]).
  struct Node {
    std::size_t i;
    double f;
  };
  Node locate(double altitude_m) const {
    const double u = std::clamp(altitude_m * inv_dh_, 0.0, static_cast<double>(altitude_samples_ - 1));
    const std::size_t i = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(altitude_samples_ - 2));
    return {i, u - static_cast<double>(i)};
  }
  int altitude_samples() const { return altitude_samples_; }
  double altitude_step_m() const { return dh_; }

  // Interpolated coefficients at a located altitude, out[b] for b < bins.
  void sigma_t(Node n, double* out) const { interpolate(coefficients_.data(), node_width(), n, bins_, out); }
  void sigma_s(Node n, double* out) const {
    interpolate(coefficients_.data() + bins_, node_width(), n, bins_, out);
  }
  // Asks the cache for what sigma_t(n) and sigma_s(n) will read (two rows
  // of 2 bins doubles), for loops that know their next altitudes early.
  void prefetch_sigma(Node n) const {
    const double* a = coefficients_.data() + n.i * node_width();
    for (const double* row : {a, a + node_width()})
      for (std::size_t k = 0; k < 2 * static_cast<std::size_t>(bins_); k += 8) __builtin_prefetch(row + k);
  }
  // All scatterers at once: out[c * bins + b].
  void sigma_s_per_scatterer(Node n, double* out) const {
    interpolate(coefficients_.data() + 2 * bins_, node_width(), n, scatterers_ * bins_, out);
  }

  // p_c,b(nu) for all scatterers and bins, out[c * bins + b], from the table.
  void phase(double nu, double* out) const;
  // The same rounded to single precision, as the marches use it.
  void phase(double nu, float* out) const;
  // The same, evaluated exactly (the reference march).
  void phase_exact(double nu, double* out) const;

  // The extinction terms (above): term_count() real ones, padded_terms()
  // stored per node (a multiple of 8, zero beyond term_count()), in blocks of
  // eight on a 64-byte line each (the quadrature loads a block as one vector).
  struct alignas(64) EightTerms {
    double value[8];
  };
  int term_count() const { return terms_; }
  int padded_terms() const { return padded_terms_; }
  // Terms k0 .. k0 + 7 of node i's profile values (k0 a multiple of 8).
  const double* term_block(std::size_t i, std::size_t k0) const {
    return term_profiles_[i * static_cast<std::size_t>(padded_terms_ / 8) + k0 / 8].value;
  }
  const double* term_spectra() const { return term_spectra_.data(); }  // [k][bin]

  const std::vector<double>& ground_albedo() const { return albedo_; }
  std::size_t memory_bytes() const;

 private:
  Node phase_node(double nu) const;
  // out[k] = table row i + f (row i + 1 - row i), k < width; rows `stride`
  // apart (in double, then stored as Out).
  template <class Out>
  static void interpolate(const double* table, std::size_t stride, Node n, int width, Out* out) {
    const double* a = table + n.i * stride;
    const double* b = a + stride;
    for (int k = 0; k < width; ++k) out[k] = static_cast<Out>(a[k] + n.f * (b[k] - a[k]));
  }
  // Values per altitude node in coefficients_: sigma_t, sigma_s, sigma_s per scatterer.
  std::size_t node_width() const { return static_cast<std::size_t>((2 + scatterers_) * bins_); }

  void build_coefficients(const Atmosphere& atmosphere, const SpectralGrid& grid);
  void build_phase(const Atmosphere& atmosphere, const SpectralGrid& grid);

  int bins_ = 0, scatterers_ = 0, altitude_samples_ = 0, phase_samples_ = 0, terms_ = 0, padded_terms_ = 0;
  double R_ = 0.0, R_top_ = 0.0, dh_ = 0.0, inv_dh_ = 0.0;
  // [node][sigma_t bins | sigma_s bins | sigma_s,c bins per scatterer]: one
  // block (2 MiB, one huge page, for the Earth at 32 bins) that a look-up
  // reads at one place per node.
  TableVector<double> coefficients_;
  std::vector<PhaseFunction> phase_functions_;         // [c][bin]
  TableVector<double> phase_table_;                    // [x node][c][bin]
  std::vector<double> albedo_;                         // [bin]
  TableVector<EightTerms> term_profiles_;              // [node][padded k / 8]
  std::vector<double> term_spectra_;                   // [padded k][bin]
};

}  // namespace skyfarm
