// The shell ray tracer against the Auer & Standish (2000) refraction integral
// (an independent quadrature of the continuous profile), Laplace's expansion,
// Bennett's (1982) formula, and the limits: zenith, horizon, limb from orbit,
// ducts.
#include "common/atmosphere/refracted_ray.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/atmosphere/air_refractive_index.h"
#include "common/atmosphere/refraction_integral.h"
#include "common/core/constants.h"

namespace skyfarm {
namespace {

constexpr double kEarth = 6371000.0;
constexpr double kArcmin = 60.0 * kRadToDeg;   // radians -> arcminutes
constexpr double kArcsec = 3600.0 * kRadToDeg;  // radians -> arcseconds

double refraction_arcmin(const RefractiveShells& shells, double elevation_deg, double altitude_m = 0.0) {
  const auto ray = trace_refracted_ray(shells, kEarth + altitude_m, 90.0 - elevation_deg, false);
  EXPECT_EQ(ray.outcome, RefractedRay::Outcome::kEscaped) << elevation_deg;
  return ray.bending_rad * kArcmin;
}

const RefractiveShells& us76_shells_550() {
  static const RefractiveShells shells = RefractiveShells::from_profile(us76_refractivity_profile(550.0));
  return shells;
}

TEST(RefractedRay, VacuumRaysAreStraight) {
  const auto shells = RefractiveShells::from_profile({[](double) { return 0.0; }, kEarth, 100000.0});
  for (double z : {0.0, 30.0, 89.0, 90.0}) {
    const auto ray = trace_refracted_ray(shells, kEarth + 500.0, z);
    EXPECT_EQ(ray.outcome, RefractedRay::Outcome::kEscaped);
    EXPECT_NEAR(ray.bending_rad, 0.0, 1e-13) << z;
    // Every vertex lies on the straight line: r sin(z - phi) = r0 sin z.
    for (const auto& v : ray.path)
      EXPECT_NEAR(v.radius_m * std::sin(z * kDegToRad - v.polar_angle_rad), (kEarth + 500.0) * std::sin(z * kDegToRad),
                  1e-6);
    // In 3D: every vertex on the line from the observer along the exit direction.
    const glm::dvec3 up{0.0, 0.0, 1.0}, forward{1.0, 0.0, 0.0};
    const glm::dvec3 o = (kEarth + 500.0) * up, d = plane_direction(ray.exit_direction_rad, up, forward);
    for (const auto& v : ray.path) {
      const glm::dvec3 q = path_point(v, up, forward) - o;
      const glm::dvec3 off = q - (q.x * d.x + q.y * d.y + q.z * d.z) * d;
      EXPECT_LT(std::sqrt(off.x * off.x + off.y * off.y + off.z * off.z), 1e-6);
    }
  }
}

TEST(RefractedRay, MatchesRefractionIntegralFromTheGround) {
  // Auer & Standish quadrature of the continuous US76 profile (split at the
  // layer bases) against the power-law shells: < 0.1 arcsec everywhere.
  const auto profile = us76_refractivity_profile(550.0);
  for (double e : {0.0, 0.5, 2.0, 10.0, 30.0, 60.0, 85.0}) {
    const double integral = refraction_integral(profile, 0.0, 90.0 - e, us76_layer_altitudes_m(), 400) * kArcsec;
    EXPECT_NEAR(refraction_arcmin(us76_shells_550(), e) * 60.0, integral, 0.1) << e;
  }
}

TEST(RefractedRay, MatchesRefractionIntegralThroughTheLimb) {
  // Rays from 100 km and from 10 km dipping through a tangent point.
  const auto profile = us76_refractivity_profile(550.0);
  for (double altitude : {10000.0, 100000.0})
    for (double dip : {1.0, 3.0, 9.5}) {
      if (altitude < 50000.0 && dip > 3.0) continue;  // 10 km sees the ground at 3.0 deg down
      const double integral =
          refraction_integral(profile, altitude, 90.0 + dip, us76_layer_altitudes_m(), 400) * kArcsec;
      ASSERT_TRUE(std::isfinite(integral));
      EXPECT_NEAR(refraction_arcmin(us76_shells_550(), -dip, altitude) * 60.0, integral, 0.2)
          << altitude << " m, " << dip << " deg down";
    }
}

TEST(RefractedRay, LaplaceExpansionUpTo70DegreesZenith) {
  // Laplace (Smart, Spherical Astronomy, ch. III): for any spherically
  // stratified atmosphere, R = A tan z - B tan^3 z with A = (n0 - 1)(1 - H/r),
  // B = (n0 - 1)(H/r - (n0 - 1)/2), H = p0 / (rho0 g0) the homogeneous height.
  // Neglected terms are ~ (n0 - 1)(H/r)^2 tan^5 z: < 0.02 arcsec at 70 deg.
  const double n1 = air::us76_refractivity(550.0, 0.0);
  const double H = 101325.0 / (1.2250 * 9.80665);
  const double A = n1 * (1.0 - H / kEarth), B = n1 * (H / kEarth - n1 / 2.0);
  for (double z : {20.0, 45.0, 60.0, 70.0}) {
    const double t = std::tan(z * kDegToRad);
    EXPECT_NEAR(refraction_arcmin(us76_shells_550(), 90.0 - z) * 60.0, (A * t - B * t * t * t) * kArcsec, 0.05) << z;
  }
  // The textbook R(45 deg) ~ 58.3 arcsec is for 10 C, 1010 hPa: US76 (15 C,
  // 1013.25 hPa) scaled by the density ratio gives 58.0 arcsec.
  const double density_ratio = (1010.0 / 1013.25) * (288.15 / 283.15);
  EXPECT_NEAR(refraction_arcmin(us76_shells_550(), 45.0) * 60.0 * density_ratio, 58.3, 0.5);
}

TEST(RefractedRay, BennettFormulaAboveFifteenDegreesAndTheHorizon) {
  // Bennett (1982), J. Navigation 35, 255: R = cot(h + 7.31 / (h + 4.4)) arcmin
  // for 10 C, 1010 hPa, ~0.07' accuracy.  US76 is scaled to those conditions by
  // density.  Above 15 deg they agree to 0.1'; at the horizon, where R depends
  // on the lapse rate near the ground, US76 (33.0' at 15 C) is within 2' of
  // Bennett's 34.5' and of the Nautical Almanac's 34'.
  const double density_ratio = (1010.0 / 1013.25) * (288.15 / 283.15);
  auto bennett = [](double h) { return 1.0 / std::tan((h + 7.31 / (h + 4.4)) * kDegToRad); };
  for (double h : {15.0, 20.0, 30.0, 45.0, 60.0, 80.0})
    EXPECT_NEAR(refraction_arcmin(us76_shells_550(), h) * density_ratio, bennett(h), 0.1) << h;
  for (double h : {5.0, 10.0}) EXPECT_NEAR(refraction_arcmin(us76_shells_550(), h) * density_ratio, bennett(h), 0.3);
  const double horizon = refraction_arcmin(us76_shells_550(), 0.0);
  EXPECT_NEAR(horizon, 33.0, 0.1);
  EXPECT_NEAR(horizon * density_ratio, bennett(0.0), 2.0);
  EXPECT_NEAR(horizon, 34.0, 2.0);
}

TEST(RefractedRay, ZenithHasNoRefraction) {
  EXPECT_NEAR(refraction_arcmin(us76_shells_550(), 90.0), 0.0, 1e-9);
  // Laplace near the zenith: R(89 deg elevation) = 57.2" tan(1 deg) = 1.0".
  EXPECT_NEAR(refraction_arcmin(us76_shells_550(), 89.0) * 60.0, 1.0, 0.01);
}

TEST(RefractedRay, DispersionGreenFlash) {
  // Horizon refraction falls with wavelength; blue minus red ~ 0.5' (the green flash).
  double previous = 1e9;
  for (double l = 400.0; l <= 700.0; l += 50.0) {
    const auto shells = RefractiveShells::from_profile(us76_refractivity_profile(l));
    const double R = refraction_arcmin(shells, 0.0);
    EXPECT_LT(R, previous) << l;
    previous = R;
  }
  const double blue = refraction_arcmin(RefractiveShells::from_profile(us76_refractivity_profile(450.0)), 0.0);
  const double red = refraction_arcmin(RefractiveShells::from_profile(us76_refractivity_profile(650.0)), 0.0);
  EXPECT_NEAR(blue - red, 0.54, 0.05);
}

TEST(RefractedRay, GrazingRaysFromTheGround) {
  // Horizontal from the ground: escapes; a hair below: ground at once.
  EXPECT_EQ(trace_refracted_ray(us76_shells_550(), kEarth, 90.0).outcome, RefractedRay::Outcome::kEscaped);
  EXPECT_EQ(trace_refracted_ray(us76_shells_550(), kEarth, 90.0 + 1e-9).outcome, RefractedRay::Outcome::kHitGround);
}

TEST(RefractedRay, LimbFromOrbitIsFiniteAndTwiceTheHorizonBending) {
  // From GEO and from 100 km the ray grazing the ground bends twice as much as
  // a horizontal ray from the ground (the path is that ray run both ways):
  // 2 x 33.0'.  Bending falls as the tangent height rises; the cost is bounded
  // by the shell count.
  const double horizon = refraction_arcmin(us76_shells_550(), 0.0);
  for (double altitude : {100000.0, 35786000.0}) {
    const double r0 = kEarth + altitude;
    double previous_bending = 1e9;
    for (double tangent_km : {0.001, 1.0, 5.0, 11.0, 20.0, 40.0, 80.0}) {
      // Apparent zenith of the ray whose tangent point is at this height: k = n(r_t) r_t.
      const double rt = kEarth + tangent_km * 1000.0;
      const double k = (1.0 + air::us76_refractivity(550.0, tangent_km * 1000.0)) * rt;
      const double n0 = altitude >= 100000.0 ? 1.0 : 1.0 + air::us76_refractivity(550.0, altitude);
      const double zenith = 180.0 - std::asin(k / (n0 * r0)) * kRadToDeg;
      const auto ray = trace_refracted_ray(us76_shells_550(), r0, zenith);
      ASSERT_EQ(ray.outcome, RefractedRay::Outcome::kEscaped) << altitude << " " << tangent_km;
      EXPECT_NEAR(ray.lowest_radius_m, rt, 0.5);
      EXPECT_LT(ray.path.size(), 2u * us76_shells_550().shell_count() + 8);
      const double bending = ray.bending_rad * kArcmin;
      EXPECT_TRUE(std::isfinite(bending));
      EXPECT_LT(bending, previous_bending);
      previous_bending = bending;
      if (tangent_km < 0.01) {
        EXPECT_NEAR(bending, 2.0 * horizon, 0.05) << altitude;
      }
    }
  }
}

// A duct: (n - 1) falls by 4e-7 /m over 50 m (steeper than 1/r = 1.6e-7 /m), so
// n r decreases with height and nearly horizontal rays turn back down.
RefractivityProfile ducting_profile(double duct_base_m) {
  return {[duct_base_m](double h) {
            const double x = std::clamp((h - duct_base_m) / 50.0, 0.0, 1.0);
            return 2.8e-4 * std::exp(-h / 8000.0) + 2e-5 * (1.0 - x);
          },
          kEarth, 100000.0};
}

TEST(RefractedRay, SurfaceDuctSendsRaysToTheGround) {
  const auto shells = RefractiveShells::from_profile(ducting_profile(0.0), 1e-8);
  const auto ray = trace_refracted_ray(shells, kEarth + 10.0, 90.0);
  EXPECT_EQ(ray.outcome, RefractedRay::Outcome::kHitGround);
  EXPECT_GT(ray.path.size(), 2u);
  // A steeper ray leaves the duct.
  EXPECT_EQ(trace_refracted_ray(shells, kEarth + 10.0, 80.0).outcome, RefractedRay::Outcome::kEscaped);
}

TEST(RefractedRay, ElevatedDuctTrapsRaysWithoutLooping) {
  // Duct 100-150 m: a horizontal ray at 120 m turns down in the duct and up
  // below it (normal air), forever: reported as trapped after one turn round
  // the planet, at bounded cost.
  const auto shells = RefractiveShells::from_profile(ducting_profile(100.0), 1e-8);
  const auto ray = trace_refracted_ray(shells, kEarth + 120.0, 90.0);
  EXPECT_EQ(ray.outcome, RefractedRay::Outcome::kTrapped);
  EXPECT_GT(ray.lowest_radius_m, kEarth);
  EXPECT_LT(ray.path.size(), 4u * shells.shell_count() + 32);
  EXPECT_EQ(trace_refracted_ray(shells, kEarth + 120.0, 70.0).outcome, RefractedRay::Outcome::kEscaped);
}

}  // namespace
}  // namespace skyfarm
