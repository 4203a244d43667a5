// The assembled atmosphere: presets, optical depths along rays against
// closed forms (Bruneton 2017, reference/functions_test.cc analytic cases).
#include "common/atmosphere/atmosphere_builder.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/atmosphere/rayleigh.h"
#include "common/core/constants.h"

namespace skyfarm {
namespace {

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

AtmosphereSpec homogeneous_spec(double sigma_per_m) {
  AtmosphereSpec s;
  s.preset = AtmospherePreset::kCustom;
  ConstituentSpec c;
  c.name = "uniform";
  c.density = LayersDensity{{{0.0, 0.0, 0.0, 0.0, 1.0}}};
  c.absorption_per_m = {{500.0}, {sigma_per_m}};
  s.constituents = {c};
  return s;
}

TEST(Atmosphere, PresetsHaveTheirConstituents) {
  AtmosphereSpec earth;
  const auto a = build_atmosphere(earth);
  ASSERT_EQ(a.constituents().size(), 3u);
  EXPECT_EQ(a.constituents()[0].name, "air");
  EXPECT_EQ(a.constituents()[1].name, "ozone");
  EXPECT_EQ(a.constituents()[2].name, "aerosol");
  AtmosphereSpec clear;
  clear.preset = AtmospherePreset::kEarthClear;
  clear.aerosol.reset();
  EXPECT_EQ(build_atmosphere(clear).constituents().size(), 2u);
  clear.ozone_du = 0.0;
  EXPECT_EQ(build_atmosphere(clear).constituents().size(), 1u);  // nothing that contributes nothing
}

TEST(Atmosphere, AerosolOpticalDepthAt550AndAngstrom) {
  AtmosphereSpec spec;
  spec.aerosol->optical_depth_550 = 0.25;
  spec.aerosol->angstrom_exponent = 1.3;
  const auto a = build_atmosphere(spec);
  EXPECT_NEAR(a.vertical_optical_depth(550.0, 0.0, 1e5, 2), 0.25, 1e-9);
  EXPECT_NEAR(a.vertical_optical_depth(440.0, 0.0, 1e5, 2), 0.25 * std::pow(440.0 / 550.0, -1.3), 1e-9);
}

TEST(Atmosphere, OzoneOpticalDepthNearChappuisPeak) {
  // 300 DU = 8.06e22 molecules m^-2; sigma(603 nm, ~220 K) ~ 5.4e-25 m^2 ->
  // tau ~ 0.044 (textbook value for the Chappuis band maximum: 0.03-0.05).
  AtmosphereSpec spec;
  const auto a = build_atmosphere(spec);
  const double tau = a.vertical_optical_depth(603.0, 0.0, 1e5, 1);
  EXPECT_GT(tau, 0.035);
  EXPECT_LT(tau, 0.050);
}

TEST(Atmosphere, HorizontalRayInUniformLayer) {
  // Bruneton functions_test "ComputeOpticalLengthToTopAtmosphereBoundary":
  // a horizontal ray at radius r through a uniform layer has
  // tau = sigma sqrt(R_top^2 - r^2).
  const double sigma = 1e-5;
  const auto a = build_atmosphere(homogeneous_spec(sigma));
  const double r = a.planet_radius_m() + 1000.0;
  const Ray ray{{0.0, 0.0, r}, {1.0, 0.0, 0.0}};
  const double expected = sigma * std::sqrt((a.top_radius_m() - r) * (a.top_radius_m() + r));
  EXPECT_LT(rel(a.optical_depth(ray, 1e9, 500.0), expected), 1e-8);
}

TEST(Atmosphere, VerticalRayInExponentialLayer) {
  // tau = sigma H (e^{-h/H} - e^{-h_top/H}) for a vertical ray from h.
  AtmosphereSpec s;
  s.preset = AtmospherePreset::kCustom;
  ConstituentSpec c;
  c.name = "exp";
  c.density = ExponentialDensity{8000.0};
  c.scattering_per_m = {{500.0}, {1.2e-5}};
  s.constituents = {c};
  const auto a = build_atmosphere(s);
  const double h = 1000.0;
  const Ray ray{{0.0, 0.0, a.planet_radius_m() + h}, {0.0, 0.0, 1.0}};
  const double expected = 1.2e-5 * 8000.0 * (std::exp(-h / 8000.0) - std::exp(-100000.0 / 8000.0));
  EXPECT_LT(rel(a.optical_depth(ray, 1e9, 500.0), expected), 1e-8);
  EXPECT_LT(rel(a.vertical_optical_depth(500.0, h, 1e5), expected), 1e-10);
}

TEST(Atmosphere, SlantRayFromSpaceStopsAtGround) {
  // From 400 km straight down: the whole column, stopped at the ground.
  AtmosphereSpec spec;
  const auto a = build_atmosphere(spec);
  const Ray ray{{0.0, 0.0, a.planet_radius_m() + 400000.0}, {0.0, 0.0, -1.0}};
  const double tau_ray = a.optical_depth(ray, 1e9, 550.0);
  EXPECT_LT(rel(tau_ray, a.vertical_optical_depth(550.0, 0.0, 1e5)), 1e-7);
}

TEST(Atmosphere, CoefficientsAreFiniteAndNonNegativeEverywhere) {
  AtmosphereSpec spec;
  const auto a = build_atmosphere(spec);
  for (double h = -10.0; h < 1.2e5; h += 97.0)
    for (double l = 230.0; l <= 2500.0; l += 13.7) {
      const double s = a.sigma_s(h, l), k = a.sigma_a(h, l);
      ASSERT_TRUE(std::isfinite(s) && std::isfinite(k) && s >= 0.0 && k >= 0.0) << h << " " << l;
    }
  EXPECT_EQ(a.sigma_t(100000.5, 500.0), 0.0);
}

TEST(Atmosphere, GroundAlbedoScalarAndSpectral) {
  AtmosphereSpec spec;
  spec.ground_albedo = 0.42;
  EXPECT_DOUBLE_EQ(build_atmosphere(spec).ground().albedo(500.0), 0.42);
  EXPECT_NEAR(build_atmosphere(spec).ground().brdf(500.0, 0.5), 0.42 / kPi, 1e-15);
  EXPECT_EQ(build_atmosphere(spec).ground().brdf(500.0, -0.1), 0.0);
  spec.ground_albedo = SpectralTable{{400.0, 700.0}, {0.1, 0.7}};
  EXPECT_NEAR(build_atmosphere(spec).ground().albedo(550.0), 0.4, 1e-12);
  EXPECT_NEAR(build_atmosphere(spec).ground().albedo(900.0), 0.7, 1e-12);
}

TEST(Atmosphere, AirPhaseFollowsBucholtzDepolarisation) {
  const auto air = earth_air();
  const double g400 = rayleigh::phase_gamma(400.0);
  // p(0) = 3 / (16 pi (1 + 2 gamma)) (1 + 3 gamma)
  EXPECT_NEAR(air.phase_at(400.0).eval(0.0), 3.0 / (16.0 * kPi * (1.0 + 2.0 * g400)) * (1.0 + 3.0 * g400), 1e-12);
}

}  // namespace
}  // namespace skyfarm
