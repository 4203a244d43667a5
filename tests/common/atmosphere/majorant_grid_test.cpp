// Majorants bound the extinction everywhere they claim to, and are
// tight enough to be useful.
#include "common/atmosphere/majorant_grid.h"

#include <gtest/gtest.h>

#include <random>

#include "common/atmosphere/atmosphere_builder.h"

namespace skyfarm {
namespace {

AtmosphereSpec custom_spec() {
  AtmosphereSpec s;
  s.preset = AtmospherePreset::kCustom;
  ConstituentSpec gas;
  gas.name = "gas";
  gas.density = ExponentialDensity{8000.0};
  gas.scattering_per_m = {{360.0, 500.0, 830.0}, {5.8e-5, 2.0e-5, 1.9e-6}};
  gas.phase = RayleighPhaseSpec{0.0};
  ConstituentSpec absorber;
  absorber.name = "absorber";
  absorber.density = LayersDensity{{{25000.0, 0.0, 0.0, 1.0 / 15000.0, -2.0 / 3.0},
                                    {0.0, 0.0, 0.0, -1.0 / 15000.0, 8.0 / 3.0}}};
  absorber.absorption_per_m = {{360.0, 600.0, 830.0}, {1e-7, 2e-6, 1e-7}};
  ConstituentSpec haze;
  haze.name = "haze";
  haze.density = TableDensity{{0.0, 1500.0, 1600.0, 3000.0}, {1.0, 0.8, 3.0, 0.0}};
  haze.scattering_per_m = {{550.0}, {1e-4}};
  haze.absorption_per_m = {{550.0}, {1e-5}};
  haze.phase = HenyeyGreensteinPhaseSpec{0.8};
  s.constituents = {gas, absorber, haze};
  return s;
}

void expect_bounds(const Atmosphere& atm, double l_min, double l_max, std::uint64_t seed) {
  const MajorantGrid grid(atm, l_min, l_max);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int i = 0; i < 200000; ++i) {
    // Half the altitudes near the ground, where the profiles vary fastest.
    const double h = (i % 2 ? atm.top_altitude_m() : 5000.0) * U(rng);
    const double l = l_min + (l_max - l_min) * U(rng);
    const double s = atm.sigma_t(h, l);
    ASSERT_LE(s, grid.sigma_maj_at(h, l) * (1.0 + 1e-12)) << "h = " << h << " m, lambda = " << l << " nm";
  }
  // Shell and bin ends exactly.
  for (std::size_t i = 0; i <= grid.shell_count(); ++i) {
    const double h = grid.shell_bottom(i);
    for (double l : {l_min, 0.5 * (l_min + l_max), l_max})
      ASSERT_LE(atm.sigma_t(h, l), grid.sigma_maj_at(h, l) * (1.0 + 1e-12)) << h << " " << l;
  }
}

TEST(MajorantGrid, BoundsEarthPresetEverywhere) {
  AtmosphereSpec spec;  // earth: air + 300 DU ozone + aerosol AOD 0.1
  expect_bounds(build_atmosphere(spec), 360.0, 830.0, 1);
  expect_bounds(build_atmosphere(spec), 280.0, 320.0, 2);  // Huggins band, temperature dependent
}

TEST(MajorantGrid, BoundsDenseHazyAndCustomAtmospheres) {
  AtmosphereSpec hazy;
  hazy.aerosol->optical_depth_550 = 3.0;
  hazy.aerosol->angstrom_exponent = -0.5;
  hazy.ozone_du = 600.0;
  expect_bounds(build_atmosphere(hazy), 360.0, 830.0, 3);
  expect_bounds(build_atmosphere(custom_spec()), 360.0, 830.0, 4);
  expect_bounds(build_atmosphere(custom_spec()), 550.0, 551.0, 5);  // one bin
}

TEST(MajorantGrid, ZeroAboveTheTopAndTightForAir) {
  AtmosphereSpec spec;
  spec.aerosol.reset();
  spec.ozone_du = 0.0;
  const auto atm = build_atmosphere(spec);
  const MajorantGrid grid(atm, 360.0, 830.0);
  EXPECT_EQ(grid.sigma_maj_at(100001.0, 500.0), 0.0);
  // For pure Rayleigh air each majorant is within its shell's density ratio
  // times the 1-nm cross-section ratio of the true value at the shell bottom.
  for (std::size_t i = 0; i < grid.shell_count(); ++i) {
    const double h = grid.shell_bottom(i);
    const double ratio = atm.sigma_t(h, 500.0) / grid.sigma_maj_at(h, 500.0);
    EXPECT_GT(ratio, 0.97) << "shell " << i << " at " << h << " m";
  }
}

}  // namespace
}  // namespace skyfarm
