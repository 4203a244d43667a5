// The LUT sky as its users see it (common/lut/lut_sky.h): twilight, views
// from space, the sun disk, stiff directions, determinism, bad input.
#include "common/lut/lut_sky.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <vector>

#include "common/atmosphere/atmosphere_builder.h"
#include "common/core/constants.h"
#include "common/lut/fibonacci_directions.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {
namespace {

glm::dvec3 dir(double zenith_deg, double azimuth_deg) {
  return direction_from_zenith_azimuth(zenith_deg * kDegToRad, azimuth_deg * kDegToRad);
}

Sun am0_sun(double zenith_deg, double azimuth_deg = 0.0) {
  SunSpec s;
  s.zenith_deg = zenith_deg;
  s.azimuth_deg = azimuth_deg;
  return Sun::from_spec(s, Location{}, std::nullopt);
}

LutResolution four_bins() {
  LutResolution r;
  r.spectral_bins = 4;
  return r;
}

// The Earth preset's tables, built once for the tests of this file.
const LutSky& earth() {
  static const LutSky sky =
      LutSky::build(build_atmosphere(AtmosphereSpec{}), am0_sun(30.0), 0.0, 360.0, 830.0, four_bins());
  return sky;
}

void expect_finite_non_negative(std::span<const double> v, const char* what) {
  for (double x : v) EXPECT_TRUE(std::isfinite(x) && x >= 0.0) << what << ": " << x;
}

// Sun 6 deg below the horizon (civil twilight): the ground is in the planet's
// shadow, but the air above ~3 km along the view still sees the sun.
TEST(LutSky, TwilightSkyGlowsTowardsTheSunkenSun) {
  const LutSky sky = earth().with_sun(am0_sun(96.0, 0.0));
  std::vector<double> towards(4), away(4), zenith(4);
  sky.radiance(dir(90.0, 0.0), towards, true);  // the exact horizon, below the sun
  sky.radiance(dir(90.0, 180.0), away, true);
  sky.radiance(dir(0.0, 0.0), zenith, true);
  for (std::size_t b = 0; b < 4; ++b) {
    EXPECT_GT(towards[b], 0.0) << b;
    EXPECT_GT(zenith[b], 0.0) << b;
    EXPECT_GT(towards[b], away[b]) << b;  // the glow is on the sun's side
  }
  expect_finite_non_negative(towards, "towards");
  expect_finite_non_negative(away, "away");
  EXPECT_EQ(sky.sanitized_values(), 0u);
}

// From 400 km: the limb (lowest point 20 km up) shines, space straight up
// is black, the sunlit planet below is bright, the sun is its disk unattenuated.
TEST(LutSky, ViewsFrom400KmAboveTheGround) {
  const LutSky sky = earth().with_sun(am0_sun(45.0, 0.0), 400000.0);
  ASSERT_TRUE(sky.observer_above_atmosphere());
  const double R = kEarthRadius_m, r = R + 400000.0;
  const double limb_zenith = 180.0 - std::asin((R + 20000.0) / r) * kRadToDeg;
  std::vector<double> limb(4), up(4), nadir(4), sun(4);
  sky.radiance(dir(limb_zenith, 90.0), limb, false);
  sky.radiance(dir(0.0, 0.0), up, true);
  sky.radiance(dir(180.0, 0.0), nadir, false);
  sky.radiance(am0_sun(45.0, 0.0).direction(), sun, true);
  for (std::size_t b = 0; b < 4; ++b) {
    EXPECT_GT(limb[b], 0.0) << b;
    EXPECT_EQ(up[b], 0.0) << b;
    EXPECT_GT(nadir[b], 0.0) << b;
    EXPECT_DOUBLE_EQ(sun[b], sky.sun_disk_radiance()[b]) << b;
  }
  for (const glm::dvec3& w : lut::fibonacci_sphere(200)) {
    sky.radiance(w, up, true);
    expect_finite_non_negative(up, "from space");
  }
  EXPECT_EQ(sky.sanitized_values(), 0u);
}

// Looking at the sun's centre from the ground: the disk adds its radiance
// times the transmittance to the top, which the transmittance LUT gives to
// 0.5 % (transmittance_lut_test); reference exp(-tau) by quadrature.
TEST(LutSky, SunDiskAddsTheAttenuatedDiskRadiance) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  const Sun sun = am0_sun(60.0, 30.0);
  const LutSky sky = earth().with_sun(sun);
  std::vector<double> with(4), without(4);
  sky.radiance(sun.direction(), with, true);
  sky.radiance(sun.direction(), without, false);
  const Ray ray{{0.0, 0.0, atm.planet_radius_m()}, sun.direction()};
  for (int b = 0; b < 4; ++b) {
    const std::size_t k = static_cast<std::size_t>(b);
    const double T = std::exp(-atm.optical_depth(ray, 1e30, sky.grid().centre_nm(b)));
    EXPECT_NEAR(with[k] - without[k], sky.sun_disk_radiance()[k] * T, 5e-3 * sky.sun_disk_radiance()[k] * T) << b;
  }
  // Just outside the disk nothing is added.
  const glm::dvec3 outside = dir(60.0 + 2.0 * sun.angular_radius_rad() * kRadToDeg, 30.0);
  sky.radiance(outside, with, true);
  sky.radiance(outside, without, false);
  for (std::size_t b = 0; b < 4; ++b) EXPECT_EQ(with[b], without[b]);
}

// Stiff directions and geometries: the exact horizon, the grazing ray on
// either side of it, zenith, nadir, a sphere of directions; suns from the
// zenith to the nadir; observers from the ground to above the top.  Every
// output (radiance with and without the disk, aerial perspective) is finite
// and >= 0, and nothing was sanitised.
TEST(LutSky, AllOutputsFiniteAndNonNegative) {
  const double R = kEarthRadius_m;
  std::vector<double> L(4), T(4);
  for (double altitude : {0.0, 1.0, 2000.0, 50000.0, 100000.0, 400000.0})
    for (double sun_zenith : {0.0, 30.0, 80.0, 90.0, 96.0, 108.0, 180.0}) {
      const LutSky sky = earth().with_sun(am0_sun(sun_zenith, 20.0), altitude);
      const double mu_h = lut::horizon_mu(R + altitude, R);
      std::vector<glm::dvec3> dirs = {dir(0.0, 0.0),   dir(180.0, 0.0),  dir(90.0, 0.0),
                                      dir(90.0, 20.0), dir(90.0, 200.0), am0_sun(sun_zenith, 20.0).direction()};
      for (double dmu : {-1e-12, 0.0, 1e-12}) {
        const double mu = mu_h + dmu;
        dirs.push_back({std::sqrt(1.0 - mu * mu), 0.0, mu});
      }
      for (const glm::dvec3& w : lut::fibonacci_sphere(60)) dirs.push_back(w);
      for (const glm::dvec3& w : dirs) {
        for (bool disk : {false, true}) {
          sky.radiance(w, L, disk);
          expect_finite_non_negative(L, "radiance");
        }
        for (double d : {0.0, 10.0, 5000.0, 64000.0, 200000.0}) {
          sky.aerial_perspective(w, d, L, T);
          expect_finite_non_negative(L, "aerial perspective");
          expect_finite_non_negative(T, "transmittance");
          for (double t : T) EXPECT_LE(t, 1.0);
        }
      }
      EXPECT_EQ(sky.sanitized_values(), 0u) << altitude << " " << sun_zenith;
    }
}

// An atmosphere that only absorbs (no scatterer at all): the sky is black,
// the ground seen from 2 km is the Lambertian reflection of the attenuated
// sun, rho/pi E T(x_g -> sun) cos(theta_s) T(observer -> x_g), and the sun
// disk is L_sun T.  Transmittances by quadrature; tolerance 1 % (two
// transmittance look-ups of 0.5 % each).
TEST(LutSky, AbsorbingAtmosphereShowsOnlyTheSunlitGroundAndTheSun) {
  AtmosphereSpec spec;
  spec.preset = AtmospherePreset::kCustom;
  spec.ground_albedo = 0.4;
  ConstituentSpec absorber;
  absorber.name = "absorber";
  absorber.density = ExponentialDensity{6000.0};
  absorber.absorption_per_m = {{400.0, 550.0, 700.0}, {4e-5, 1e-5, 2.5e-5}};
  spec.constituents = {absorber};
  const Atmosphere atm = build_atmosphere(spec);
  const Sun sun = am0_sun(40.0, 90.0);
  const double altitude = 2000.0, R = atm.planet_radius_m();
  const LutSky sky = LutSky::build(atm, sun, altitude, 360.0, 830.0, four_bins());
  std::vector<double> L(4);
  sky.radiance(dir(20.0, 0.0), L, false);
  for (double x : L) EXPECT_EQ(x, 0.0);
  const glm::dvec3 o(0.0, 0.0, R + altitude), v = dir(130.0, 200.0);
  const double t_g = lut::distance_to_ground(R + altitude, v.z, R);
  const glm::dvec3 x_g = o + t_g * v, n = glm::normalize(x_g);
  const double cos_s = glm::dot(n, sun.direction());
  sky.radiance(v, L, false);
  for (int b = 0; b < 4; ++b) {
    const double l = sky.grid().centre_nm(b);
    const double T_view = std::exp(-atm.optical_depth(Ray{o, v}, t_g, l));
    const double T_sun = std::exp(-atm.optical_depth(Ray{x_g + 0.01 * n, sun.direction()}, 1e30, l));
    const double expected = 0.4 * kInvPi * sky.sun_irradiance()[static_cast<std::size_t>(b)] * T_sun * cos_s * T_view;
    EXPECT_NEAR(L[static_cast<std::size_t>(b)], expected, 0.01 * expected) << l << " nm";
  }
  sky.radiance(sun.direction(), L, true);  // the disk over a black sky
  for (int b = 0; b < 4; ++b) {
    const double T = std::exp(-atm.optical_depth(Ray{o, sun.direction()}, 1e30, sky.grid().centre_nm(b)));
    const double expected = sky.sun_disk_radiance()[static_cast<std::size_t>(b)] * T;
    EXPECT_NEAR(L[static_cast<std::size_t>(b)], expected, 5e-3 * expected) << b;
  }
  EXPECT_EQ(sky.sanitized_values(), 0u);
}

// with_sun shares the atmosphere's tables and gives bit-identical results
// to a fresh build; the tables take memory.
TEST(LutSky, WithSunMatchesAFreshBuildExactly) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  const LutSky fresh = LutSky::build(atm, am0_sun(70.0, 120.0), 1500.0, 360.0, 830.0, four_bins());
  const LutSky reused = earth().with_sun(am0_sun(70.0, 120.0), 1500.0);
  std::vector<double> a(4), b(4);
  for (const glm::dvec3& w : lut::fibonacci_sphere(50)) {
    fresh.radiance(w, a, true);
    reused.radiance(w, b, true);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(a[k], b[k]);
  }
  EXPECT_GT(fresh.memory_bytes(), 1000000u);
  EXPECT_EQ(fresh.clamped_multiple_scattering_nodes(), 0);
}

TEST(LutSky, RejectsBadInput) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  LutResolution zero_bins;
  zero_bins.spectral_bins = 0;
  EXPECT_THROW(LutSky::build(atm, am0_sun(30.0), 0.0, 360.0, 830.0, zero_bins), std::invalid_argument);
  EXPECT_THROW(LutSky::build(atm, am0_sun(30.0), 0.0, 830.0, 360.0, four_bins()), std::invalid_argument);
  std::vector<double> too_small(3);
  EXPECT_THROW(earth().radiance(dir(0.0, 0.0), too_small, false), std::invalid_argument);
  std::vector<double> L(4, -1.0);
  earth().radiance(glm::dvec3(0.0), L, false);  // no direction: no light
  for (double x : L) EXPECT_EQ(x, 0.0);
}

}  // namespace
}  // namespace skyfarm
