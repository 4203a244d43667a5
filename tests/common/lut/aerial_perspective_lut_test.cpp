// The aerial-perspective table against the per-ray reference march
// (common/lut/aerial_perspective_lut.h, LutSky::raymarch_aerial_perspective).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/atmosphere/atmosphere_builder.h"
#include "common/core/constants.h"
#include "common/lut/lut_sky.h"
#include "common/lut/shell_geometry.h"

namespace skyfarm {
namespace {

Sun am0_sun(double zenith_deg, double azimuth_deg) {
  SunSpec s;
  s.zenith_deg = zenith_deg;
  s.azimuth_deg = azimuth_deg;
  return Sun::from_spec(s, Location{}, std::nullopt);
}

// An observer 2 km up looking down at the ground (2-40 km away) and along the
// sky to 5 and 50 km: the table (32 x 32 directions x 32 quadratic slices,
// one march step per slice) against a 400-step march of the same ray.
// Measured worst (100 deg, 11.6 km to the ground, between two of the 16
// ground rows): in-scattered 2.2 %, transmittance 0.0045 absolute.
// Tolerances 4 % and 0.01.
TEST(LutAerialPerspective, MatchesTheMarchUpToTheGround) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  LutResolution res;
  res.spectral_bins = 4;
  const double altitude = 2000.0, R = atm.planet_radius_m(), r = R + altitude;
  const LutSky sky = LutSky::build(atm, am0_sun(40.0, 0.0), altitude, 360.0, 830.0, res);
  const glm::dvec3 o(0.0, 0.0, r);
  std::vector<double> L(4), T(4), L_ref(4), T_ref(4);
  double worst_L = 0.0, worst_T = 0.0;
  for (double zenith : {93.0, 95.0, 100.0, 120.0, 150.0, 180.0, 60.0, 89.0})
    for (double azimuth : {0.0, 90.0, 180.0}) {
      const glm::dvec3 v = direction_from_zenith_azimuth(zenith * kDegToRad, azimuth * kDegToRad);
      const bool ground = lut::ray_hits_ground(r, v.z, R);
      for (double d :
           ground ? std::vector<double>{lut::distance_to_ground(r, v.z, R)} : std::vector<double>{5000.0, 50000.0}) {
        ASSERT_LE(d, 64000.0) << zenith;
        sky.aerial_perspective(v, d, L, T);
        sky.raymarch_aerial_perspective(o, v, d, L_ref, T_ref, 400);
        for (std::size_t b = 0; b < 4; ++b) {
          worst_L = std::max(worst_L, std::abs(L[b] / L_ref[b] - 1.0));
          worst_T = std::max(worst_T, std::abs(T[b] - T_ref[b]));
          EXPECT_NEAR(L[b], L_ref[b], 0.04 * L_ref[b]) << zenith << "/" << azimuth << " d " << d << " bin " << b;
          EXPECT_NEAR(T[b], T_ref[b], 1e-2) << zenith << "/" << azimuth << " d " << d << " bin " << b;
        }
      }
    }
  RecordProperty("worst_relative_in_scattered", std::to_string(worst_L));
  RecordProperty("worst_absolute_transmittance", std::to_string(worst_T));
  EXPECT_EQ(sky.sanitized_values(), 0u);
}

// Zero distance: nothing added, nothing dimmed; beyond the table's 64 km the
// look-up marches instead (and agrees with the march).
TEST(LutAerialPerspective, ZeroDistanceAndBeyondTheTable) {
  const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  LutResolution res;
  res.spectral_bins = 2;
  const LutSky sky = LutSky::build(atm, am0_sun(60.0, 90.0), 0.0, 400.0, 700.0, res);
  std::vector<double> L(2), T(2), L_ref(2), T_ref(2);
  const glm::dvec3 v = direction_from_zenith_azimuth(85.0 * kDegToRad, 1.0);
  sky.aerial_perspective(v, 0.0, L, T);
  for (std::size_t b = 0; b < 2; ++b) {
    EXPECT_EQ(L[b], 0.0);
    EXPECT_EQ(T[b], 1.0);
  }
  sky.aerial_perspective(v, 150000.0, L, T);
  sky.raymarch_aerial_perspective({0.0, 0.0, atm.planet_radius_m()}, v, 150000.0, L_ref, T_ref, 64);
  for (std::size_t b = 0; b < 2; ++b) {
    EXPECT_GT(L[b], 0.0);
    EXPECT_DOUBLE_EQ(L[b], L_ref[b]);
    EXPECT_DOUBLE_EQ(T[b], T_ref[b]);
  }
}

}  // namespace
}  // namespace skyfarm
