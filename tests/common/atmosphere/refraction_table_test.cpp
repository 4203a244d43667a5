// The refraction table against direct ray tracing (its interpolation error,
// the figures quoted in refraction_table.h and docs/physics.md), its inverse,
// and the sun just below the geometric horizon.
#include "common/atmosphere/refraction_table.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/atmosphere/refracted_ray.h"
#include "common/atmosphere/refractive_shells.h"
#include "common/core/constants.h"

namespace skyfarm {
namespace {

constexpr double kEarth = 6371000.0;

RefractionTable::Options at_550() {
  RefractionTable::Options o;
  o.wavelengths_nm = {550.0};
  return o;
}

// Largest |table - direct trace| (arcsec) at the mid-points of both segments' grids.
struct MidpointErrors {
  double below = 0.0, above = 0.0;
};
MidpointErrors midpoint_errors(double altitude_m) {
  const auto o = at_550();
  const RefractionTable table(altitude_m, o);
  const auto shells = RefractiveShells::from_profile(us76_refractivity_profile(550.0), o.max_refractivity_step);
  const double r0 = kEarth + altitude_m;
  const double e_min = table.lowest_apparent_elevation_deg(550.0);
  const double e0 = std::min(0.0, -std::acos(std::min(1.0, shells.top_radius_m() / r0)) * kRadToDeg);
  auto direct = [&](double e) {
    const auto ray = trace_refracted_ray(shells, r0, 90.0 - e, false);
    return ray.outcome == RefractedRay::Outcome::kEscaped ? ray.bending_rad * kRadToDeg : 0.0;
  };
  MidpointErrors m;
  const int n = o.elevation_nodes;
  for (int j = 0; j + 1 < n; ++j) {
    const double e_below = e_min + (e0 - e_min) * (j + 0.5) / (n - 1);
    if (e0 > e_min) m.below = std::max(m.below, std::abs(*table.refraction_deg(e_below, 550.0) - direct(e_below)));
    const double u = (j + 0.5) / (n - 1);
    const double e_above = e0 + (90.0 - e0) * u * u;
    m.above = std::max(m.above, std::abs(*table.refraction_deg(e_above, 550.0) - direct(e_above)));
  }
  m.below *= 3600.0;
  m.above *= 3600.0;
  return m;
}

TEST(RefractionTable, InterpolationErrorAtGridMidpoints) {
  // Measured (arcsec): ground 0.13 above the horizon; 10 km 0.05 above, 0.04
  // below; 100 km (the top) and GEO below the horizon up to ~15 and ~23, where
  // the tangent point crosses a US76 layer base (R has a square-root cusp there).
  const auto ground = midpoint_errors(0.0);
  EXPECT_LT(ground.above, 0.2);
  const auto high = midpoint_errors(10000.0);
  EXPECT_LT(high.above, 0.1);
  EXPECT_LT(high.below, 0.1);
  const auto top = midpoint_errors(100000.0);
  EXPECT_LT(top.below, 30.0);
  EXPECT_LT(top.above, 1e-6);  // rays above the horizon never enter the air
  const auto geo = midpoint_errors(35786000.0);
  EXPECT_LT(geo.below, 30.0);
  EXPECT_LT(geo.above, 1e-6);
}

TEST(RefractionTable, WavelengthInterpolationAtTwentyNanometres) {
  // Linear in 1/lambda^2 between 20 nm nodes, at the horizon where R is largest: < 0.02".
  const RefractionTable table(0.0);
  for (double l : {390.0, 450.0, 530.0, 650.0, 770.0}) {
    RefractionTable::Options o;
    o.wavelengths_nm = {l};
    const RefractionTable direct(0.0, o);
    EXPECT_NEAR(*table.refraction_deg(0.0, l) * 3600.0, *direct.refraction_deg(0.0, l) * 3600.0, 0.02) << l;
  }
}

TEST(RefractionTable, InverseRoundTrip) {
  for (double altitude : {0.0, 2000.0, 35786000.0}) {
    const RefractionTable table(altitude, at_550());
    const double e_min = table.lowest_apparent_elevation_deg(550.0);
    for (double e = e_min + 1e-6; e < 90.0; e += 0.37) {
      const auto t = table.true_elevation_deg(e, 550.0);
      ASSERT_TRUE(t);
      EXPECT_LT(*t, e + 1e-12);
      const auto back = table.apparent_elevation_deg(*t, 550.0);
      ASSERT_TRUE(back);
      EXPECT_NEAR(*back, e, 1e-9) << altitude;
    }
    EXPECT_FALSE(table.true_elevation_deg(e_min - 0.01, 550.0));
  }
}

TEST(RefractionTable, SunBelowTheGeometricHorizonIsStillSeen) {
  // Sea level, 550 nm: the sun's centre at true zenith 90.5 deg appears above
  // the horizon (horizon refraction 33.0' > 30'); at 90.6 deg it is hidden.
  const RefractionTable table(0.0, at_550());
  const auto apparent = table.apparent_elevation_deg(-0.5, 550.0);
  ASSERT_TRUE(apparent);
  EXPECT_GT(*apparent, 0.0);
  EXPECT_LT(*apparent, 0.1);
  EXPECT_FALSE(table.apparent_elevation_deg(-0.6, 550.0));
  EXPECT_NEAR(*table.refraction_deg(0.0, 550.0) * 60.0, 33.0, 0.1);
  EXPECT_NEAR(*table.refraction_deg(90.0, 550.0), 0.0, 1e-12);
}

TEST(RefractionTable, DipOfTheHorizonFromAltitude) {
  // Refraction lifts the horizon: the dip is less than the geometric
  // acos(R / (R + h)) but, with k ~ 0.15-0.2 (the ray's curvature in units of
  // the Earth's), more than 0.85 of it.
  for (double h : {2000.0, 10000.0}) {
    const RefractionTable table(h, at_550());
    const double geometric = std::acos(kEarth / (kEarth + h)) * kRadToDeg;
    const double dip = -table.lowest_apparent_elevation_deg(550.0);
    EXPECT_LT(dip, geometric);
    EXPECT_GT(dip, 0.85 * geometric);
  }
}

}  // namespace
}  // namespace skyfarm
