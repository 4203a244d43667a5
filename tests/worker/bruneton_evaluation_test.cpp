// Bruneton's evaluation setting (worker/bruneton_evaluation.h): case times
// and sun positions, the scanner's 81 directions, the 31 wavelengths, the
// RMSE, and the example probe api/examples/probe_bruneton_2017.json that
// carries them.
#include "worker/bruneton_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

#include "api/probe_request.h"
#include "common/sun/solar_position.h"
#include "tests/support/test_files.h"

namespace skyfarm {
namespace {

TEST(BrunetonEvaluationCases, SeventeenQuarterHoursFromHalfPastNineEdt) {
  const auto cases = bruneton_cases();
  ASSERT_EQ(cases.size(), 17u);
  EXPECT_EQ(cases.front().local_time, "09:30");
  EXPECT_EQ(cases.front().time.to_iso8601(), "2013-05-27T13:30:00Z");
  EXPECT_EQ(cases[9].local_time, "11:45");
  EXPECT_EQ(cases[9].time.to_iso8601(), "2013-05-27T15:45:00Z");
  EXPECT_EQ(cases.back().local_time, "13:30");
  EXPECT_EQ(cases.back().time.to_iso8601(), "2013-05-27T17:30:00Z");
  for (std::size_t i = 1; i < cases.size(); ++i) {
    EXPECT_EQ(cases[i].index, static_cast<int>(i));
    EXPECT_EQ(cases[i].time.unix_seconds - cases[i - 1].time.unix_seconds, 900);
  }
}

TEST(BrunetonEvaluationCases, SunZenithAgreesWithTheNoaaSolarCalculator) {
  // Independent check: the NOAA Solar Calculator's equations (Meeus,
  // "Astronomical Algorithms", ch. 25, low precision; the NOAA ESRL
  // spreadsheet NOAA_Solar_Calculations_day.xls), geometric zenith without
  // refraction, at 42.44337 N, 76.48163 W, evaluated for each case time.
  // Their stated accuracy is about 0.01 deg for these years; the project's
  // NREL SPA agrees to 0.005 deg.
  const double noaa_zenith_deg[] = {48.937, 46.208, 43.507, 40.845, 38.235, 35.691, 33.233, 30.886, 28.680,
                                    26.653, 24.854, 23.336, 22.159, 21.383, 21.051, 21.186, 21.778};
  const auto cases = bruneton_cases();
  for (const auto& c : cases) {
    SCOPED_TRACE(c.local_time);
    EXPECT_NEAR(solar_position(bruneton_location(), c.time).zenith_deg, noaa_zenith_deg[c.index], 0.02);
  }
  // Morning: the sun in the east-south-east, crossing south near 13:00 EDT
  // (local solar noon at 76.48 W in late May, EDT = UTC-4).
  EXPECT_NEAR(solar_position(bruneton_location(), cases.front().time).azimuth_deg, 98.1, 0.2);
  EXPECT_LT(solar_position(bruneton_location(), cases[13].time).azimuth_deg, 180.0);
  EXPECT_GT(solar_position(bruneton_location(), cases[15].time).azimuth_deg, 180.0);
}

TEST(BrunetonEvaluationDirections, EightyOneDirectionsOnFiveRings) {
  const auto dirs = bruneton_directions();
  ASSERT_EQ(dirs.size(), 81u);
  // Ring k (k = 0..4, zenith outwards) has radius 2k/9 in the disk, so
  // cos(zenith) = 1 - (2k/9)^2, and 8k directions (1 at the zenith):
  // elevations 90, 71.9187, 53.3665, 33.749, 12.1151 deg, the numbers in
  // Kider's file names.
  const double elevation_deg[] = {90.0, 71.9187, 53.3665, 33.749, 12.1151};
  std::map<int, int> per_ring;
  for (const auto& d : dirs) {
    int ring = -1;
    for (int k = 0; k < 5; ++k)
      if (std::abs(90.0 - d.zenith_deg - elevation_deg[k]) < 1e-3) ring = k;
    ASSERT_GE(ring, 0) << d.zenith_deg;
    ++per_ring[ring];
    EXPECT_NEAR(std::cos(d.zenith_deg * std::numbers::pi / 180.0), 1.0 - (2.0 * ring / 9.0) * (2.0 * ring / 9.0),
                1e-12);
    EXPECT_GE(d.azimuth_deg, 0.0);
    EXPECT_LT(d.azimuth_deg, 360.0);
  }
  EXPECT_EQ(per_ring, (std::map<int, int>{{0, 1}, {1, 8}, {2, 16}, {3, 24}, {4, 32}}));
  // The outer ring is every 11.25 deg of azimuth, as in the file names.
  std::map<long, int> outer;
  for (const auto& d : dirs)
    if (d.zenith_deg > 70.0) ++outer[std::lround(d.azimuth_deg * 100.0)];
  ASSERT_EQ(outer.size(), 32u);
  for (int k = 0; k < 32; ++k) EXPECT_EQ(outer.count(std::lround(k * 1125.0)), 1u) << k;
  // Grid cell (8, 4) is north (azimuth 0) on the outer ring, (4, 8) east:
  // the first axis points north, the second east.
  EXPECT_NEAR(dirs[8 * 9 + 4].azimuth_deg, 0.0, 1e-12);
  EXPECT_NEAR(dirs[4 * 9 + 8].azimuth_deg, 90.0, 1e-12);
  EXPECT_EQ(dirs[4 * 9 + 4].zenith_deg, 0.0);
}

TEST(BrunetonEvaluationWavelengths, ThirtyOneSamplesFrom360To712Point5) {
  const auto w = bruneton_wavelengths_nm();
  ASSERT_EQ(w.size(), 31u);
  EXPECT_EQ(w.front(), 360.0);
  EXPECT_EQ(w[1], 371.75);
  EXPECT_EQ(w.back(), 712.5);
  // The next sample, 724.25 nm, is past the compared range's 720 nm.
  EXPECT_GT(w.back() + 11.75, 720.0);
}

TEST(BrunetonEvaluationRmse, KnownArrays) {
  // Constant offset c everywhere: RMSE = c.
  const std::vector<std::vector<double>> ref(81, std::vector<double>(31, 0.05));
  auto model = ref;
  for (auto& row : model)
    for (auto& v : row) v += 0.003;
  EXPECT_NEAR(bruneton_case_rmse(model, ref), 0.003, 1e-15);
  // One value off by e among n: RMSE = e / sqrt(n).
  model = ref;
  model[40][7] += 0.02;
  EXPECT_NEAR(bruneton_case_rmse(model, ref), 0.02 / std::sqrt(81.0 * 31.0), 1e-15);
  // Errors +a and -a alternate: they square, they do not cancel.
  const std::vector<std::vector<double>> r2 = {{1.0, 1.0}, {1.0, 1.0}};
  const std::vector<std::vector<double>> m2 = {{1.5, 0.5}, {0.5, 1.5}};
  EXPECT_DOUBLE_EQ(bruneton_case_rmse(m2, r2), 0.5);
  // The total is the RMS of the cases' scores, not their mean: 3 and 4 -> sqrt(12.5).
  EXPECT_DOUBLE_EQ(bruneton_total_rmse({3.0, 4.0}), std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(bruneton_total_rmse({3.07}), 3.07);
  EXPECT_THROW(bruneton_case_rmse({}, {}), std::invalid_argument);
  EXPECT_THROW(bruneton_case_rmse(m2, {{1.0, 1.0}}), std::invalid_argument);
  EXPECT_THROW(bruneton_case_rmse({{1.0}, {1.0, 2.0}}, r2), std::invalid_argument);
  EXPECT_THROW(bruneton_total_rmse({}), std::invalid_argument);
}

TEST(BrunetonEvaluationExample, ProbeExampleCarriesTheEvaluationSetting) {
  const api::ProbeRequest r =
      api::parse_probe_request(testing::read_text(testing::kExamples / "probe_bruneton_2017.json"));
  EXPECT_EQ(r.location.latitude_deg, bruneton_location().latitude_deg);
  EXPECT_EQ(r.location.longitude_deg, bruneton_location().longitude_deg);
  ASSERT_TRUE(r.time.has_value());
  EXPECT_EQ(r.time->unix_seconds, bruneton_cases().front().time.unix_seconds);
  EXPECT_EQ(r.wavelengths_nm, bruneton_wavelengths_nm());
  const auto dirs = bruneton_directions();
  ASSERT_EQ(r.directions.size(), dirs.size());
  for (std::size_t d = 0; d < dirs.size(); ++d) {
    EXPECT_NEAR(r.directions[d].zenith_deg, dirs[d].zenith_deg, 1e-4) << d;
    EXPECT_NEAR(r.directions[d].azimuth_deg, dirs[d].azimuth_deg, 1e-4) << d;
  }
  // Bruneton's demo atmosphere: 6360 km planet, 60 km atmosphere, albedo 0.1.
  EXPECT_EQ(r.atmosphere.preset, AtmospherePreset::kCustom);
  EXPECT_EQ(r.atmosphere.planet_radius_m, 6360000.0);
  EXPECT_EQ(r.atmosphere.top_altitude_m, 60000.0);
  EXPECT_EQ(r.atmosphere.constituents.size(), 3u);
}

}  // namespace
}  // namespace skyfarm
