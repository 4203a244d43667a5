// Test support: an independent plane-parallel solution of radiative transfer
// in a homogeneous slab over a black ground, by adding-doubling (the oracle
// of the path tracer's clouds).
//
// Method (Hansen & Travis 1974, Space Sci. Rev. 16, 527, sec. 3.3; Wiscombe
// 1977, J. Atmos. Sci. 34, 1408 for delta-M):
//   - the azimuth-averaged (m = 0 Fourier) radiance, which alone carries the
//     hemispheric fluxes, on double-Gauss quadrature (Gauss-Legendre on each
//     hemisphere, streams/2 nodes each);
//   - the phase function as its Legendre series, chi_l = 2 pi int p P_l dmu
//     (computed from PhaseFunction::eval by a fine quadrature), delta-M
//     truncated to `streams` terms: the forward-peak fraction f = chi_streams
//     is treated as unscattered, tau' = (1 - omega f) tau,
//     omega' = omega (1 - f) / (1 - omega f), chi'_l = (chi_l - f) / (1 - f);
//     f = 0 (no change) for the isotropic and other smooth phases;
//   - a layer of tau_0 = tau / 2^n <= 2^-20 tau (and <= 1e-8) initialised by
//     exact single scattering, doubled n times (the sun as one extra column).
//
// Parameters
//   tau      vertical optical depth of the slab (> 0)
//   omega    single-scattering albedo, [0, 1]
//   phase    the phase function (1/sr), any PhaseFunction
//   mu0      cosine of the sun's zenith angle, (0, 1]
//   streams  total number of quadrature directions (even, 4-256)
// Returns flux ratios normalised by mu0 E0 (E0: the sun's irradiance at
// normal incidence): reflectance, diffuse and direct transmittance.  As in
// DISORT, direct is the true exp(-tau/mu0) and diffuse the rest of the
// delta-M total (the truncated forward peak is diffuse light near the sun);
// the angular transmission_function lacks that peak.
// Throws std::invalid_argument on a parameter outside its range.
#pragma once
#include <vector>

#include "common/atmosphere/phase_function.h"

namespace skyfarm::testing {

struct SlabFluxes {
  double reflectance = 0.0;
  double diffuse_transmittance = 0.0;
  double direct_transmittance = 0.0;
  double total_transmittance() const { return diffuse_transmittance + direct_transmittance; }
  // The delta-M forward fraction used (0: no truncation).
  double delta_m_fraction = 0.0;
  // The azimuth-averaged reflected and diffusely transmitted radiance at the
  // quadrature cosines mu_i of one hemisphere, as reflection functions
  // pi I(mu_i) / (mu0 E0) (so that reflectance = 2 int_0^1 r(mu) mu dmu).
  std::vector<double> mu;
  std::vector<double> reflection_function;
  std::vector<double> transmission_function;
};

SlabFluxes adding_doubling_slab(double tau, double omega, const PhaseFunction& phase, double mu0, int streams = 48);

// Legendre moments chi_0..chi_lmax of a phase function (chi_0 = 1, chi_1 = g),
// by Gauss-Legendre quadrature on a grid dense near the forward direction.
std::vector<double> phase_legendre_moments(const PhaseFunction& phase, int lmax);

// Gauss-Legendre nodes and weights on [a, b].
void gauss_legendre(int n, double a, double b, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace skyfarm::testing
