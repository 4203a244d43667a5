// The multiple-scattering bands (common/lut/multiple_scattering_bands.h):
// the harmonics against their closed forms, the phase moments against
// analytic values, the table against a brute-force quadrature that shares
// neither its directions nor its control variate, and the bands' effect on
// an isotropic atmosphere (none, by Funk-Hecke).
#include "common/lut/multiple_scattering_bands.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "common/atmosphere/atmosphere_builder.h"
#include "common/core/constants.h"
#include "common/lut/fibonacci_directions.h"
#include "common/lut/lut_sky.h"
#include "common/lut/multiple_scattering_lut.h"
#include "common/lut/segment_integral.h"
#include "common/lut/shell_geometry.h"
#include "common/lut/spectral_grid.h"

namespace skyfarm {
namespace {

// Orthonormal over the sphere (midpoint rule in cos(theta) and phi, 400 x
// 800 nodes: exact to ~1e-5 for band <= 4), and the closed forms of the
// first bands (Sloan 2008, table 1, without the Condon-Shortley sign).
TEST(MirrorHarmonics, OrthonormalAndTheirClosedForms) {
  constexpr int L = lut::kMaxHarmonicBand, K = lut::mirror_harmonic_count(L);
  std::vector<double> gram(K * K, 0.0), Y(K);
  const int n_mu = 400, n_phi = 800;
  for (int i = 0; i < n_mu; ++i)
    for (int j = 0; j < n_phi; ++j) {
      const double z = -1.0 + 2.0 * (i + 0.5) / n_mu, phi = 2.0 * kPi * (j + 0.5) / n_phi;
      const double s = std::sqrt(1.0 - z * z), x = s * std::cos(phi), y = s * std::sin(phi);
      lut::mirror_harmonics(L, z, x, y * y, Y.data());
      const double dw = 2.0 / n_mu * 2.0 * kPi / n_phi;
      for (int a = 0; a < K; ++a)
        for (int b = 0; b < K; ++b) gram[a * K + b] += Y[a] * Y[b] * dw;
    }
  for (int a = 0; a < K; ++a)
    for (int b = 0; b < K; ++b) EXPECT_NEAR(gram[a * K + b], a == b ? 1.0 : 0.0, 2e-4) << a << " " << b;

  const double x = 0.36, y = -0.48, z = 0.8;  // a unit vector
  lut::mirror_harmonics(2, z, x, y * y, Y.data());
  const double c1 = std::sqrt(3.0 / (4.0 * kPi));
  EXPECT_NEAR(Y[0], 0.5 / std::sqrt(kPi), 1e-14);
  EXPECT_NEAR(Y[lut::mirror_harmonic_index(1, 0)], c1 * z, 1e-14);
  EXPECT_NEAR(Y[lut::mirror_harmonic_index(1, 1)], c1 * x, 1e-14);
  EXPECT_NEAR(Y[lut::mirror_harmonic_index(2, 0)], std::sqrt(5.0 / (16.0 * kPi)) * (3.0 * z * z - 1.0), 1e-14);
  EXPECT_NEAR(Y[lut::mirror_harmonic_index(2, 1)], std::sqrt(15.0 / (4.0 * kPi)) * x * z, 1e-14);
  EXPECT_NEAR(Y[lut::mirror_harmonic_index(2, 2)], std::sqrt(15.0 / (16.0 * kPi)) * (x * x - y * y), 1e-14);
}

AtmosphereSpec one_scatterer(PhaseSpec phase) {
  AtmosphereSpec spec;
  spec.preset = AtmospherePreset::kCustom;
  spec.ground_albedo = 0.0;
  ConstituentSpec c;
  c.name = "scatterer";
  c.density = ExponentialDensity{8000.0};
  c.scattering_per_m = {{400.0, 720.0}, {1.2e-5, 0.6e-5}};
  c.phase = phase;
  spec.constituents = {c};
  return spec;
}

// Henyey-Greenstein: g_l = g^l (its generating function); Rayleigh without
// depolarisation, 3/(16 pi)(1 + mu^2): g_1 = 0, g_2 = 1/10.
TEST(MultipleScatteringBands, PhaseMomentsMatchTheirClosedForms) {
  const SpectralGrid grid(400.0, 720.0, 2);
  for (double g : {0.0, 0.7, 0.9}) {
    const MediumTable medium = MediumTable::build(build_atmosphere(one_scatterer(HenyeyGreensteinPhaseSpec{g})), grid);
    const std::vector<double> m = phase_moments(medium, 4);
    for (int l = 0; l <= 4; ++l)
      for (int b = 0; b < 2; ++b) EXPECT_NEAR(m[static_cast<std::size_t>(l * 2 + b)], std::pow(g, l), 2e-4) << g << l;
  }
  const MediumTable rayleigh = MediumTable::build(build_atmosphere(one_scatterer(RayleighPhaseSpec{0.0})), grid);
  const std::vector<double> m = phase_moments(rayleigh, 2);
  EXPECT_NEAR(m[0], 1.0, 1e-6);
  EXPECT_NEAR(m[2], 0.0, 1e-6);
  EXPECT_NEAR(m[4], 0.1, 1e-6);
}

// The table's a_lm (l >= 1) at its nodes against a brute-force quadrature of
// the same integral: 8192 spherical-Fibonacci directions (no rings, no mirror
// symmetry, no control variate), 200 steps each, the same first-order light
// (exact phase functions, the transmittance table for the sun, the ground's
// direct sun and sky irradiance).  Earth preset (aerosols g = 0.7), 4 bins.
// Error relative to the largest |a_lm| of the node and bin, measured worst:
// a fine table (32 rings x 16 azimuths, 32 steps) 2.3 %, so the table
// computes the right integral; the default (12 x 6, 8 steps) 19 %, its own
// discretisation, which moves the sky by < 0.3 % RMS against the path
// tracer (docs/experiments/2026-12-07-anisotropic-multiple-scattering.md).
// Tolerances 3 % and 25 %.
// The tables the bands are built from, Earth preset over 400-720 nm.
struct EarthTables {
  explicit EarthTables(int bins)
      : medium(MediumTable::build(build_atmosphere(AtmosphereSpec{}), SpectralGrid(400.0, 720.0, bins))),
        T(TransmittanceLut::build(medium)),
        ms(MultipleScatteringLut::build(medium, T)),
        gi(GroundIrradianceLut::build(medium, T, ms)) {}
  MediumTable medium;
  TransmittanceLut T;
  MultipleScatteringLut ms;
  GroundIrradianceLut gi;
};

TEST(MultipleScatteringBands, MatchBruteForceQuadrature) {
  const EarthTables tables(4);
  const MediumTable& medium = tables.medium;
  const TransmittanceLut& T = tables.T;
  const GroundIrradianceLut& gi = tables.gi;
  const MultipleScatteringBands bands = MultipleScatteringBands::build(medium, T, gi);
  const MultipleScatteringBands fine = MultipleScatteringBands::build(medium, T, gi, 2, 24, 8, 32, 16, 32);
  const int B = 4, C = medium.scatterers(), K = bands.harmonics();
  const double R = medium.planet_radius_m(), top = medium.top_altitude_m();
  const std::vector<glm::dvec3> dirs = lut::fibonacci_sphere(8192);
  const double dw = 4.0 * kPi / static_cast<double>(dirs.size());
  constexpr int kSteps = 200;
  std::vector<float> table(static_cast<std::size_t>(K * B)), fine_table(static_cast<std::size_t>(K * B));
  std::vector<double> s_t(B), s_c(C * B), phase(C * B), Tsun(B), Tr(B), E(B), Y(6);
  // Nodes: altitude nodes 0 and 2 (h = top (2/7)^2), mu_s nodes 23 (zenith),
  // 17 (mu_s = 0.385), 13 (0.033), 11 (-0.033).
  for (int j : {0, 2})
    for (int col : {23, 17, 13, 11}) {
      const double h = top * (j / 7.0) * (j / 7.0), x = -1.0 + 2.0 * col / 23.0;
      const double mu_s = x * (0.3 + 0.7 * std::abs(x)), sin_s = std::sqrt(1.0 - mu_s * mu_s);
      const glm::dvec3 o(0.0, 0.0, R + h), s(sin_s, 0.0, mu_s);
      std::vector<double> ref(static_cast<std::size_t>(K * B), 0.0);
      for (const glm::dvec3& w : dirs) {
        const double r = R + h, mu = w.z;
        const bool hits = lut::ray_hits_ground(r, mu, R);
        const double t_end = hits ? lut::distance_to_ground(r, mu, R) : lut::distance_to_top(r, mu, R + top);
        std::vector<double> L1(B, 0.0);
        std::fill(Tr.begin(), Tr.end(), 1.0);
        medium.phase_exact(glm::dot(w, s), phase.data());
        for (int k = 0; k < kSteps; ++k) {
          const double dt = t_end / kSteps, t = (k + 0.5) * dt;
          const glm::dvec3 p = o + t * w;
          const double rp = glm::length(p);
          const MediumTable::Node node = medium.locate(std::max(0.0, rp - R));
          medium.sigma_t(node, s_t.data());
          medium.sigma_s_per_scatterer(node, s_c.data());
          T.to_top(rp, glm::dot(p, s) / rp, Tsun.data());
          for (int b = 0; b < B; ++b) {
            double integral;
            const double Tseg = lut::T_and_in_scattering_integral(s_t[b], dt, &integral);
            for (int c = 0; c < C; ++c) L1[b] += Tr[b] * integral * s_c[c * B + b] * phase[c * B + b] * Tsun[b];
            Tr[b] *= Tseg;
          }
        }
        if (hits) {
          const glm::dvec3 g = o + t_end * w;
          const double mu_g = glm::dot(g, s) / glm::length(g);
          std::fill(E.begin(), E.end(), 0.0);
          if (mu_g > 0.0) {
            T.to_top(R, mu_g, E.data());
            for (double& e : E) e *= mu_g;
          }
          gi.lookup_add(mu_g, E.data());
          for (int b = 0; b < B; ++b) L1[b] += Tr[b] * medium.ground_albedo()[b] * kInvPi * E[b];
        }
        lut::mirror_harmonics(2, w.z, w.x, w.y * w.y, Y.data());
        for (int k = 1; k < K; ++k)
          for (int b = 0; b < B; ++b) ref[k * B + b] += dw * Y[k] * L1[b];
      }
      bands.coefficients(h, mu_s, table.data());
      fine.coefficients(h, mu_s, fine_table.data());
      for (int b = 0; b < B; ++b) {
        double scale = 0.0;
        for (int k = 1; k < K; ++k) scale = std::max(scale, std::abs(ref[k * B + b]));
        ASSERT_GT(scale, 0.0);
        for (int k = 1; k < K; ++k) {
          EXPECT_NEAR(fine_table[k * B + b], ref[k * B + b], 0.03 * scale)
              << "fine, altitude node " << j << " mu_s " << mu_s << " harmonic " << k << " bin " << b;
          EXPECT_NEAR(table[k * B + b], ref[k * B + b], 0.25 * scale)
              << "default, altitude node " << j << " mu_s " << mu_s << " harmonic " << k << " bin " << b;
        }
      }
    }
}

// Isotropic scatterers have g_l = 0 for l >= 1: the bands add nothing and
// the LUT sky is Hillaire's to rounding.
TEST(MultipleScatteringBands, AddNothingToAnIsotropicAtmosphere) {
  const Atmosphere atm = build_atmosphere(one_scatterer(HenyeyGreensteinPhaseSpec{0.0}));
  const Sun sun(70.0, 0.0, 0.2666, PiecewiseLinear::constant(1.8));
  LutResolution with, without;
  with.spectral_bins = without.spectral_bins = 2;
  without.bands = 0;
  const LutSky a = LutSky::build(atm, sun, 0.0, 400.0, 720.0, with);
  const LutSky b = LutSky::build(atm, sun, 0.0, 400.0, 720.0, without);
  std::vector<double> La(2), Lb(2);
  for (double zenith : {0.0, 45.0, 80.0, 89.0, 120.0})
    for (double azimuth : {0.0, 90.0, 180.0}) {
      const glm::dvec3 v = direction_from_zenith_azimuth(zenith * kDegToRad, azimuth * kDegToRad);
      a.radiance(v, La, false);
      b.radiance(v, Lb, false);
      for (int k = 0; k < 2; ++k) EXPECT_NEAR(La[k], Lb[k], 1e-5 * Lb[k]) << zenith << " " << azimuth;
    }
}

TEST(MultipleScatteringBands, RejectsBadResolution) {
  const EarthTables tables(2);
  const MediumTable& medium = tables.medium;
  const TransmittanceLut& T = tables.T;
  const GroundIrradianceLut& gi = tables.gi;
  EXPECT_THROW(MultipleScatteringBands::build(medium, T, gi, lut::kMaxHarmonicBand + 1), std::invalid_argument);
  EXPECT_THROW(MultipleScatteringBands::build(medium, T, gi, 2, 1), std::invalid_argument);
  EXPECT_THROW(MultipleScatteringBands::build(medium, T, gi, 2, 24, 8, 12, 0), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
