// The per-bin coefficient tables against the atmosphere they tabulate
// (common/lut/medium_table.h).
#include "common/lut/medium_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "common/atmosphere/atmosphere_builder.h"

namespace skyfarm {
namespace {

// Linear interpolation on 2048 nodes (49 m) errs by at most (dh/H)^2/8 of an
// exponential of scale height H: 2.1e-4 for the 1.2 km aerosol layer.  The
// profiles' own tables have kinks between our nodes (measured: 0.58 % at
// 689 nm next to the aerosol table's knot at 1 km; the optical depth of the
// 49 m cell barely notices), so the tolerance is 1 % relative plus
// 1e-12 m^-1 absolute (ozone's zero above its table).
TEST(LutMediumTable, InterpolatedCoefficientsMatchTheAtmosphere) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});  // air, ozone, aerosols
  const SpectralGrid grid(360.0, 830.0, 5);
  const MediumTable m = MediumTable::build(atm, grid);
  ASSERT_EQ(m.scatterers(), 2);  // air and aerosols; ozone only absorbs
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<double> s_t(5), s_s(5), s_c(10);
  for (int k = 0; k < 200; ++k) {
    const double h = k == 0 ? 0.0 : (k == 1 ? atm.top_altitude_m() : atm.top_altitude_m() * U(rng) * U(rng));
    const MediumTable::Node n = m.locate(h);
    m.sigma_t(n, s_t.data());
    m.sigma_s(n, s_s.data());
    m.sigma_s_per_scatterer(n, s_c.data());
    for (int b = 0; b < 5; ++b) {
      const double l = grid.centre_nm(b);
      const double t = atm.sigma_t(h, l), s = atm.sigma_s(h, l);
      EXPECT_NEAR(s_t[static_cast<std::size_t>(b)], t, 1e-2 * t + 1e-12) << h << " m, " << l << " nm";
      EXPECT_NEAR(s_s[static_cast<std::size_t>(b)], s, 1e-2 * s + 1e-12) << h << " m, " << l << " nm";
      EXPECT_NEAR(s_c[static_cast<std::size_t>(b)] + s_c[static_cast<std::size_t>(5 + b)],
                  s_s[static_cast<std::size_t>(b)], 1e-12 * s + 1e-20);
    }
  }
  EXPECT_EQ(m.ground_albedo().size(), 5u);
  EXPECT_DOUBLE_EQ(m.ground_albedo()[0], 0.3);
}

// The tabulated phase functions (512 nodes in x = sin(theta/2)) against the
// exact ones: Rayleigh (quartic in x) to 3e-5 (measured 1.0e-5), Henyey-
// Greenstein g = 0.7 to 0.5 % (its forward peak is the steepest part).
TEST(LutMediumTable, TabulatedPhaseFunctionsMatchTheExactOnes) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  const SpectralGrid grid(400.0, 700.0, 3);
  const MediumTable m = MediumTable::build(atm, grid);
  std::vector<double> p(6), q(6);
  for (int k = 0; k <= 2000; ++k) {
    const double nu = std::cos(3.14159265358979 * k / 2000.0);
    m.phase(nu, p.data());
    m.phase_exact(nu, q.data());
    for (std::size_t j = 0; j < 6; ++j) EXPECT_NEAR(p[j], q[j], (j < 3 ? 3e-5 : 5e-3) * q[j]) << nu << " " << j;
  }
}

// The extinction as separable terms (medium_table.h): the Earth preset has
// air, aerosols and the ozone temperature columns that some altitude uses,
// and the terms add up to sigma_t at every node (to rounding).
TEST(LutMediumTable, ExtinctionTermsAddUpToSigmaT) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  const SpectralGrid grid(360.0, 830.0, 32);
  const MediumTable m = MediumTable::build(atm, grid, 512);
  EXPECT_GE(m.term_count(), 4);  // air, aerosols, >= 2 ozone columns
  EXPECT_LE(m.term_count(), 7);
  EXPECT_EQ(m.padded_terms() % 8, 0);
  const std::size_t K = static_cast<std::size_t>(m.padded_terms()), B = 32;
  std::vector<double> s_t(B);
  const std::size_t last_cell = static_cast<std::size_t>(m.altitude_samples() - 2);
  for (int i = 0; i < m.altitude_samples(); ++i) {
    // Node i itself, as MediumTable::locate gives it: the last node is the
    // end of the last cell (a Node past it would read beyond the table).
    const std::size_t n = static_cast<std::size_t>(i);
    m.sigma_t(n <= last_cell ? MediumTable::Node{n, 0.0} : MediumTable::Node{last_cell, 1.0}, s_t.data());
    for (std::size_t b = 0; b < B; ++b) {
      double sum = 0.0;
      for (std::size_t k = 0; k < K; ++k)
        sum += m.term_block(static_cast<std::size_t>(i), k / 8 * 8)[k % 8] * m.term_spectra()[k * B + b];
      EXPECT_NEAR(sum, s_t[b], 1e-13 * s_t[b]) << "node " << i << " bin " << b;
    }
  }
  AtmosphereSpec custom;
  custom.preset = AtmospherePreset::kCustom;
  ConstituentSpec a, b;
  a.name = "scatterer";
  a.density = ExponentialDensity{8000.0};
  a.scattering_per_m = {{400.0, 700.0}, {1e-5, 2e-6}};
  b.name = "absorber";
  b.density = ExponentialDensity{1000.0};
  b.absorption_per_m = {{550.0}, {3e-6}};
  custom.constituents = {a, b};
  const MediumTable two = MediumTable::build(build_atmosphere(custom), grid, 64);
  EXPECT_EQ(two.term_count(), 2);
  EXPECT_EQ(two.padded_terms(), 8);
}

}  // namespace
}  // namespace skyfarm
