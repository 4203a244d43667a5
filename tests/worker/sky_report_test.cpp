// `skyfarm-worker info`'s apparent sun: ray-traced US76 refraction at 550 nm
// next to the SPA's Bennett-based correction.
#include "worker/sky_report.h"

#include <gtest/gtest.h>

#include <string>

namespace skyfarm {
namespace {

nlohmann::json apparent_sun(double zenith_deg, double altitude_m = 0.0) {
  const std::string body = R"({"sun": {"zenith_deg": )" + std::to_string(zenith_deg) +
                           R"(, "azimuth_deg": 180}, "camera": {"projection": "fisheye"}, "location": {"altitude_m": )" +
                           std::to_string(altitude_m) + "}}";
  return sky_report(api::parse_render_request(body))["apparent_sun"];
}

TEST(SkyReportApparentSun, AgreesWithBennettWellAboveTheHorizon) {
  // Bennett / SPA (scaled to the US76 ground state) and the ray-traced US76
  // agree to 0.1' above 15 deg (tests/common/atmosphere/refracted_ray_test.cpp).
  const auto a = apparent_sun(60.0);
  ASSERT_TRUE(a["visible"].get<bool>());
  EXPECT_NEAR(a["refraction_arcmin"].get<double>(), a["bennett_refraction_arcmin"].get<double>(), 0.1);
  EXPECT_NEAR(a["apparent_zenith_deg"].get<double>(), 60.0 - a["refraction_arcmin"].get<double>() / 60.0, 1e-9);
  EXPECT_NEAR(a["refraction_arcmin"].get<double>(), 1.65, 0.01);  // Laplace: 57.2" tan 60 deg
}

TEST(SkyReportApparentSun, SunHalfADegreeBelowTheGeometricHorizonIsSeen) {
  const auto a = apparent_sun(90.5);
  ASSERT_TRUE(a["visible"].get<bool>());
  EXPECT_GT(a["apparent_elevation_deg"].get<double>(), 0.0);
  EXPECT_FALSE(apparent_sun(91.0)["visible"].get<bool>());
  // From 10 km the horizon dips by ~3 deg: the sun at true zenith 92 deg is seen.
  EXPECT_TRUE(apparent_sun(92.0, 10000.0)["visible"].get<bool>());
  const std::string text = format_sky_report(sky_report(api::parse_render_request(
      std::string(R"({"sun": {"zenith_deg": 60, "azimuth_deg": 180}, "camera": {"projection": "fisheye"}})"))));
  EXPECT_NE(text.find("apparent sun"), std::string::npos);
}

}  // namespace
}  // namespace skyfarm
