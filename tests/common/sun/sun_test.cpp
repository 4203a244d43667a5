// The sun as a light source: AM0 spectrum, disk radiance and its sampling.
#include "common/sun/sun.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <random>

#include "common/core/constants.h"
#include "common/sun/solar_spectrum.h"
#include "tests/support/chi2.h"

namespace skyfarm {
namespace {

TEST(SolarSpectrum, Am0IntegratesToTheSolarConstant) {
  // ASTM E-490-00a: trapezoidal total 1366.09 W m^-2 (solar constant 1366.1; data/README.md §2).
  const auto& E = am0_irradiance();
  EXPECT_NEAR(E.integral(E.x_min(), E.x_max()), 1366.1, 0.1);
  // Mean over 450-500 nm is 1.99 W m^-2 nm^-1 (data/README.md).
  EXPECT_NEAR(E.integral(450.0, 500.0) / 50.0, 1.99, 0.01);
}

Sun test_sun(double angular_radius_deg) {
  SunSpec spec;
  spec.zenith_deg = 30.0;
  spec.azimuth_deg = 120.0;
  spec.angular_radius_deg = angular_radius_deg;
  return Sun::from_spec(spec, Location{}, std::nullopt);
}

TEST(Sun, DiskRadianceReproducesTheIrradiance) {
  // E = L pi sin^2(alpha) for a uniform disk.
  const Sun sun = test_sun(0.2666);
  const double alpha = 0.2666 * kDegToRad;
  EXPECT_NEAR(sun.radiance(550.0) * kPi * std::sin(alpha) * std::sin(alpha), sun.irradiance(550.0), 1e-12);
  EXPECT_NEAR(sun.irradiance(550.0), am0_irradiance()(550.0), 1e-12);  // no time: 1 AU
  // Monte Carlo over the sampled disk: mean(L cos(theta) / pdf) -> E.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double sum = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    double pdf = 0.0;
    const glm::dvec3 w = sun.sample_direction(U(rng), U(rng), &pdf);
    ASSERT_TRUE(sun.contains(w));
    ASSERT_NEAR(glm::length(w), 1.0, 1e-14);
    sum += sun.radiance(550.0) * glm::dot(w, sun.direction()) / pdf;
  }
  EXPECT_NEAR(sum / n, sun.irradiance(550.0), 1e-6 * sun.irradiance(550.0));
}

TEST(Sun, SolidAngleKeepsPrecisionForTheRealDisk) {
  // Omega = 2 pi (1 - cos alpha) = 6.7993e-5 sr for alpha = 0.2666 deg.
  const double alpha = 0.2666 * kDegToRad;
  EXPECT_NEAR(test_sun(0.2666).solid_angle_sr(), 2.0 * kPi * (alpha * alpha / 2.0 - std::pow(alpha, 4) / 24.0),
              1e-15);
}

TEST(Sun, DirectionFromZenithAndAzimuthClockwiseFromNorth) {
  SunSpec spec;
  spec.zenith_deg = 90.0;
  spec.azimuth_deg = 90.0;  // on the eastern horizon
  const Sun sun = Sun::from_spec(spec, Location{}, std::nullopt);
  EXPECT_NEAR(sun.direction().x, 1.0, 1e-15);
  EXPECT_NEAR(sun.direction().z, 0.0, 1e-15);
}

TEST(Sun, NeedsATimeOrBothAngles) {
  SunSpec spec;
  spec.zenith_deg = 10.0;
  EXPECT_THROW(Sun::from_spec(spec, Location{}, std::nullopt), std::invalid_argument);
}

TEST(Sun, TimeGivesPositionAndDistanceScaledIrradiance) {
  // Near perihelion (2024-01-03, R = 0.98331 AU per USNO/IMCCE) the irradiance is AM0 / R^2.
  const auto t = parse_iso8601("2024-01-03T00:00:00Z");
  ASSERT_TRUE(t);
  const Sun sun = Sun::from_spec(SunSpec{}, Location{40.0, -105.0, 1600.0}, t);
  EXPECT_NEAR(sun.distance_au(), 0.98331, 2e-4);
  EXPECT_NEAR(sun.irradiance(550.0), am0_irradiance()(550.0) / (sun.distance_au() * sun.distance_au()), 1e-12);
  // Angles given with a time replace the computed position but keep the distance.
  SunSpec angles;
  angles.zenith_deg = 45.0;
  angles.azimuth_deg = 180.0;
  const Sun both = Sun::from_spec(angles, Location{}, t);
  EXPECT_DOUBLE_EQ(both.zenith_deg(), 45.0);
  EXPECT_NEAR(both.distance_au(), 0.98331, 2e-4);
}

TEST(Sun, PointSunIsADelta) {
  const Sun sun = test_sun(0.0);
  EXPECT_TRUE(sun.is_point());
  double pdf = 0.0;
  EXPECT_EQ(sun.sample_direction(0.3, 0.7, &pdf), sun.direction());
  EXPECT_EQ(sun.radiance(500.0), sun.irradiance(500.0));
  EXPECT_FALSE(sun.contains(sun.direction()));
}

// Chi-square of the disk sampling (significance 0.01).  The real 0.27-degree
// disk is too small for (cos theta, phi) bins about the sun, so its samples
// are tested in the disk's own coordinates: (1 - cos theta) / (1 - cos alpha)
// and phi / 2 pi must both be uniform; a 20-degree disk is tested on the sphere.
TEST(Sun, DiskSamplingChiSquare) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const Sun small = test_sun(0.2666);
  const Frame frame(small.direction());
  const double one_minus_cos_alpha = 2.0 * std::pow(std::sin(0.5 * small.angular_radius_rad()), 2);
  std::vector<double> radial, azimuthal;
  for (int i = 0; i < 200000; ++i) {
    double pdf = 0.0;
    const glm::dvec3 local = frame.to_local(small.sample_direction(U(rng), U(rng), &pdf));
    const glm::dvec3 diff = local - glm::dvec3(0.0, 0.0, 1.0);
    radial.push_back(0.5 * glm::dot(diff, diff) / one_minus_cos_alpha);
    double phi = std::atan2(local.y, local.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    azimuthal.push_back(phi / (2.0 * kPi));
  }
  const auto uniform = [](double) { return 1.0; };
  EXPECT_GT(testing::chi2_test_1d(uniform, radial, 0.0, 1.0, 50).p_value, 0.01);
  EXPECT_GT(testing::chi2_test_1d(uniform, azimuthal, 0.0, 1.0, 50).p_value, 0.01);

  SunSpec big_spec;
  big_spec.zenith_deg = 0.0;  // centred on +z, the harness's axis
  big_spec.azimuth_deg = 0.0;
  big_spec.angular_radius_deg = 20.0;
  const Sun big = Sun::from_spec(big_spec, Location{}, std::nullopt);
  std::vector<glm::dvec3> dirs;
  for (int i = 0; i < 200000; ++i) {
    double pdf = 0.0;
    dirs.push_back(big.sample_direction(U(rng), U(rng), &pdf));
  }
  const auto r = testing::chi2_test_sphere([&](const glm::dvec3& w) { return big.pdf(w); }, dirs, 40, 40);
  EXPECT_GT(r.p_value, 0.01) << r.detail;
}

}  // namespace
}  // namespace skyfarm
