// Physics validation of the path tracer against closed forms.
// Statistical tests use fixed seeds; tolerances are 4 standard errors of the
// Monte Carlo estimate plus, where stated, a modelling allowance.
#include <gtest/gtest.h>

#include "tests/support/sun_specs.h"
#include "tests/support/thin_layer.h"

#include <cmath>
#include <memory>
#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/core/math.h"
#include "common/core/integrate.h"
#include "common/geometry/sphere_intersection.h"
#include "common/render/radiance_control.h"
#include "common/render/radiance_probe.h"
#include "common/render/shadow_guide.h"
#include "common/render/volume_path_integrator.h"

namespace skyfarm {
namespace {

SunSpec sun_at(double zenith_deg, double azimuth_deg, double radius_deg = 0.2666) {
  return testing::sun_spec(zenith_deg, azimuth_deg, radius_deg);
}

// Radiance along `ray` at four wavelengths, the hero rotated among the four
// slots per sample as the renderer's rotated strata do: per wavelength (in
// the order given) the mean and its standard error.
struct RotatedHeroMoments {
  std::array<double, 4> mean{}, se{};
  PathCounters counters;
};

RotatedHeroMoments radiance_with_rotated_hero(const VolumePathIntegrator& integrator, const Ray& ray,
                                              const std::array<double, 4>& lambdas, int n, std::uint64_t seed) {
  RotatedHeroMoments m;
  SampledSpectrum sum(0.0), sum_sq(0.0);
  for (int s = 0; s < n; ++s) {
    Sampler sampler(seed, 0, static_cast<std::uint64_t>(s));
    const int rot = static_cast<int>(4.0 * sampler.next());
    SampledWavelengths wl;
    for (int i = 0; i < 4; ++i) wl.lambda_nm[i] = lambdas[static_cast<std::size_t>((i + rot) % 4)];
    wl.pdf.fill(1.0);
    const SampledSpectrum L = integrator.radiance(ray, wl, sampler, &m.counters);
    for (int i = 0; i < 4; ++i) {
      const int k = (i + rot) % 4;
      sum[k] += L[i];
      sum_sq[k] += L[i] * L[i];
    }
  }
  for (std::size_t k = 0; k < 4; ++k) {
    m.mean[k] = sum[static_cast<int>(k)] / n;
    m.se[k] = std::sqrt(std::max(0.0, sum_sq[static_cast<int>(k)] / n - m.mean[k] * m.mean[k]) / n);
  }
  return m;
}

// --- Transmittance: ratio tracking is unbiased at every wavelength of a path.
TEST(IntegratorPhysics, RatioTrackingTransmittanceEqualsExpMinusTauAtAllWavelengths) {
  AtmosphereSpec spec;  // earth: air, ozone, aerosols
  const Scene scene = Scene::from_specs(spec, sun_at(30.0, 0.0), Location{}, std::nullopt, 300.0, 830.0);
  const VolumePathIntegrator integrator(scene);
  const Ray ray{scene.observer(), direction_from_zenith_azimuth(75.0 * kDegToRad, 1.0)};
  SampledWavelengths wl;
  wl.lambda_nm = {600.0, 320.0, 450.0, 800.0};  // hero in the middle of the range, others both sides
  wl.pdf.fill(1.0);
  const int n = 20000;
  SampledSpectrum sum(0.0), sum_sq(0.0);
  PathCounters counters;
  for (int s = 0; s < n; ++s) {
    Sampler sampler(5, 0, static_cast<std::uint64_t>(s));
    const SampledSpectrum T = integrator.transmittance(ray, 1e30, wl, sampler, &counters);
    sum += T;
    sum_sq += T * T;
  }
  for (int i = 0; i < kWavelengthsPerPath; ++i) {
    const double exact = std::exp(-scene.atmosphere().optical_depth(ray, 1e30, wl.lambda_nm[i]));
    const double mean = sum[i] / n;
    const double se = std::sqrt(std::max(0.0, sum_sq[i] / n - mean * mean) / n);
    EXPECT_NEAR(mean, exact, 4.0 * se + 1e-12) << wl.lambda_nm[i] << " nm";
  }
}

// --- The direct sun through an absorbing-only atmosphere, seen by camera
// paths (delta tracking + spectral MIS): L_i = L_sun(l_i) exp(-tau_i) for
// every wavelength of the path.  The hero is rotated among the four slots per
// sample, as the renderer's rotated strata do.
TEST(IntegratorPhysics, DirectSunThroughAbsorberMatchesBeerLambertAtAllWavelengths) {
  AtmosphereSpec spec;
  spec.preset = AtmospherePreset::kCustom;
  ConstituentSpec absorber;
  absorber.name = "absorber";
  absorber.density = ExponentialDensity{6000.0};
  absorber.absorption_per_m = {{400.0, 550.0, 700.0}, {4e-5, 1e-5, 2.5e-5}};
  spec.constituents = {absorber};
  const Scene scene = Scene::from_specs(spec, sun_at(40.0, 90.0), Location{}, std::nullopt, 400.0, 700.0);
  const VolumePathIntegrator integrator(scene);
  const Ray to_sun{scene.observer(), scene.sun().direction()};
  const std::array<double, 4> lambdas = {420.0, 500.0, 560.0, 690.0};
  const RotatedHeroMoments m = radiance_with_rotated_hero(integrator, to_sun, lambdas, 20000, 9);
  EXPECT_EQ(m.counters.nonfinite, 0u);
  for (std::size_t k = 0; k < 4; ++k) {
    const double l = lambdas[k];
    const double exact = scene.sun().radiance(l) * std::exp(-scene.atmosphere().optical_depth(to_sun, 1e30, l));
    EXPECT_NEAR(m.mean[k], exact, 4.0 * m.se[k] + 1e-9 * exact) << l << " nm";
  }
}

// --- Optically thin single scattering against its integral.
// A homogeneous 2 km layer (sigma_s = 5e-6 /m, tau = 0.01) over a black
// ground, point sun, first scattering order only (max_depth 1, so with a
// point sun the estimate is delta tracking + NEE, no MIS):
//   L = E int_0^s_max sigma_s p(Theta) exp(-sigma_s s) exp(-sigma_s l_sun(s)) ds,
// with l_sun(s) the distance from the scattering point to the layer top
// towards the sun, evaluated exactly on the sphere.
TEST(IntegratorPhysics, ThinLayerSingleScatteringMatchesIntegral) {
  const double sigma_s = 5e-6, top = 2000.0, g = 0.5;
  const AtmosphereSpec spec = testing::thin_hg_layer(sigma_s, top, g);
  const Scene scene = Scene::from_specs(spec, sun_at(30.0, 180.0, 0.0), Location{}, std::nullopt, 500.0, 600.0);
  const double lambda = 550.0;
  const glm::dvec3 view = direction_from_zenith_azimuth(60.0 * kDegToRad, 0.0);
  const glm::dvec3 wsun = scene.sun().direction();
  const double R = scene.atmosphere().planet_radius_m();
  const Ray view_ray{scene.observer(), view};
  const double s_max = distance_to_sphere(view_ray, R + top);
  const double mu = glm::dot(view, -wsun);  // scattering angle between sunlight's propagation and -view
  const double p = (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g + 2.0 * g * mu, 1.5));
  // (HG of the angle between incoming propagation -wsun and outgoing -view.)
  const double E = scene.sun().irradiance(lambda);
  const double expected = integrate_adaptive_simpson(
      [&](double s) {
        const glm::dvec3 x = view_ray.at(s);
        const double l_sun = distance_to_sphere(Ray{x, wsun}, R + top);
        return E * sigma_s * p * std::exp(-sigma_s * s) * std::exp(-sigma_s * l_sun);
      },
      0.0, s_max, 1e-10);

  // Both single-scattering estimators: delta tracking with NEE at the
  // collisions, and the explicit sunlit-segment estimator.
  for (bool explicit_single : {false, true}) {
    SCOPED_TRACE(explicit_single ? "explicit sunlit-segment estimator" : "delta tracking + NEE");
    IntegratorOptions options;
    options.max_depth = 1;
    options.explicit_single_scattering = explicit_single;
    const VolumePathIntegrator integrator(scene, options);
    SampledWavelengths wl;
    wl.lambda_nm.fill(lambda);
    wl.pdf.fill(1.0);
    const int n = 400000;
    double sum = 0.0, sum_sq = 0.0;
    PathCounters counters;
    for (int s = 0; s < n; ++s) {
      Sampler sampler(21, 0, static_cast<std::uint64_t>(s));
      const double L = integrator.radiance(view_ray, wl, sampler, &counters)[0];
      sum += L;
      sum_sq += L * L;
    }
    const double mean = sum / n, se = std::sqrt((sum_sq / n - mean * mean) / n);
    EXPECT_NEAR(mean, expected, 4.0 * se) << "relative error " << (mean - expected) / expected;
    EXPECT_LT(se / expected, 0.015);  // 4 standard errors: the test sees a 6 % error
  }
}

// --- Twilight single scattering (sun 95 deg, below the horizon): the
// observer is in the planet's shadow and only air high along the view is lit.
// A homogeneous layer to 60 km with sigma_s ~ lambda^-4, black ground,
// point sun, first order only, four wavelengths with the hero rotated
// (the sunlit-segment estimator's spectral MIS):
//   L(l) = E(l) int_lit sigma_s(l) p(Theta) exp(-sigma_s(l) (s + l_sun(s))) ds,
// lit = the points whose ray to the sun misses the planet.
TEST(IntegratorPhysics, TwilightSingleScatteringMatchesIntegralAtAllWavelengths) {
  const double top = 60000.0, g = 0.3;
  AtmosphereSpec spec = testing::thin_hg_layer(1.0, top, g);
  const std::array<double, 4> lambdas = {420.0, 500.0, 580.0, 680.0};
  auto sigma_of = [](double l) { return 2e-7 * std::pow(550.0 / l, 4.0); };
  spec.constituents[0].scattering_per_m = {{400.0, 420.0, 500.0, 580.0, 680.0, 700.0},
                                           {sigma_of(400.0), sigma_of(420.0), sigma_of(500.0), sigma_of(580.0),
                                            sigma_of(680.0), sigma_of(700.0)}};
  const Scene scene = Scene::from_specs(spec, sun_at(95.0, 0.0, 0.0), Location{}, std::nullopt, 400.0, 700.0);
  const glm::dvec3 view = direction_from_zenith_azimuth(75.0 * kDegToRad, 0.0);  // towards the sun's azimuth
  const glm::dvec3 wsun = scene.sun().direction();
  const double R = scene.atmosphere().planet_radius_m();
  const Ray view_ray{scene.observer(), view};
  const double s_max = distance_to_sphere(view_ray, R + top);
  const double mu = glm::dot(view, -wsun);
  const double p = (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g + 2.0 * g * mu, 1.5));
  std::array<double, 4> expected{};
  for (int k = 0; k < 4; ++k) {
    const double l = lambdas[static_cast<std::size_t>(k)], sigma_s = scene.atmosphere().constituents()[0].k_scattering.eval(l, 0.0);
    expected[static_cast<std::size_t>(k)] = integrate_adaptive_simpson(
        [&](double s) {
          const Ray to_sun{view_ray.at(s), wsun};
          if (intersect_sphere(to_sun, R).hit && intersect_sphere(to_sun, R).t_far > 0.0) return 0.0;
          return scene.sun().irradiance(l) * sigma_s * p * std::exp(-sigma_s * (s + distance_to_sphere(to_sun, R + top)));
        },
        0.0, s_max, 1e-14);
    ASSERT_GT(expected[static_cast<std::size_t>(k)], 0.0);
  }
  IntegratorOptions options;
  options.max_depth = 1;
  const VolumePathIntegrator integrator(scene, options);
  const RotatedHeroMoments m = radiance_with_rotated_hero(integrator, view_ray, lambdas, 200000, 23);
  EXPECT_EQ(m.counters.nonfinite, 0u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(m.mean[k], expected[k], 4.0 * m.se[k])
        << lambdas[k] << " nm, relative error " << (m.mean[k] - expected[k]) / expected[k];
    EXPECT_LT(m.se[k] / expected[k], 0.01) << lambdas[k] << " nm";  // sharp enough to see 4 %
  }
}

// --- The twilight guide (directions in the planet's shadow drawn partly
// from a lobe towards the lit air) changes the variance, not the mean: with
// and without it, up to the second order, the Earth sky at twilight towards
// the sun's azimuth agrees within 4 combined standard errors at four
// wavelengths (the hero rotated).
TEST(IntegratorPhysics, TwilightGuideKeepsTheMean) {
  const Scene scene = Scene::from_specs(AtmosphereSpec{}, sun_at(96.0, 0.0, 0.0), Location{}, std::nullopt, 400.0, 700.0);
  const Ray ray{scene.observer(), direction_from_zenith_azimuth(77.5 * kDegToRad, 0.0)};
  const std::array<double, 4> lambdas = {430.0, 510.0, 590.0, 660.0};
  IntegratorOptions guided, unguided;
  guided.max_depth = unguided.max_depth = 2;
  unguided.twilight_guide_fraction = 0.0;
  const RotatedHeroMoments a = radiance_with_rotated_hero(VolumePathIntegrator(scene, guided), ray, lambdas, 60000, 31);
  const RotatedHeroMoments b =
      radiance_with_rotated_hero(VolumePathIntegrator(scene, unguided), ray, lambdas, 60000, 32);
  EXPECT_EQ(a.counters.nonfinite + b.counters.nonfinite, 0u);
  for (std::size_t k = 0; k < 4; ++k) {
    const double se = std::hypot(a.se[k], b.se[k]);
    EXPECT_NEAR(a.mean[k], b.mean[k], 4.0 * se) << lambdas[k] << " nm";
    EXPECT_LT(se / b.mean[k], 0.1) << lambdas[k] << " nm";
  }
}

// --- The shadow guide (shadow_guide.h) draws part of the directions at
// vertices where the sun is below the local horizontal from a table of the
// light arriving there; the pdf is the mixture's, so the mean is unchanged:
// up to third order, with and without it (and without the lobe it replaces),
// towards the sun low and away from it high, within 4 combined standard
// errors at four wavelengths.
TEST(IntegratorPhysics, ShadowGuideKeepsTheMean) {
  const Scene scene = Scene::from_specs(AtmosphereSpec{}, sun_at(96.0, 0.0, 0.0), Location{}, std::nullopt, 400.0, 700.0);
  const std::array<double, 4> lambdas = {430.0, 510.0, 590.0, 660.0};
  IntegratorOptions guided, unguided;
  guided.max_depth = unguided.max_depth = 3;
  guided.shadow_guide = std::make_shared<const ShadowGuide>(scene);
  unguided.twilight_guide_fraction = 0.0;
  const VolumePathIntegrator a(scene, guided), b(scene, unguided);
  int d = 0;
  for (const glm::dvec2 zenith_azimuth : {glm::dvec2(80.0, 0.0), glm::dvec2(50.0, 180.0)}) {
    const Ray ray{scene.observer(),
                  direction_from_zenith_azimuth(zenith_azimuth.x * kDegToRad, zenith_azimuth.y * kDegToRad)};
    const RotatedHeroMoments ma = radiance_with_rotated_hero(a, ray, lambdas, 40000, 61 + d);
    const RotatedHeroMoments mb = radiance_with_rotated_hero(b, ray, lambdas, 40000, 71 + d);
    ++d;
    EXPECT_EQ(ma.counters.nonfinite + mb.counters.nonfinite, 0u);
    for (std::size_t k = 0; k < 4; ++k) {
      const double se = std::hypot(ma.se[k], mb.se[k]);
      EXPECT_NEAR(ma.mean[k], mb.mean[k], 4.0 * se) << "zenith " << zenith_azimuth.x << ", " << lambdas[k] << " nm";
      EXPECT_LT(se / mb.mean[k], 0.15) << "zenith " << zenith_azimuth.x << ", " << lambdas[k] << " nm";
    }
  }
}

// --- Russian roulette against a lower threshold in the planet's shadow
// keeps the mean (any survival probability does), keeps twilight paths
// alive longer (more collisions per path: the paths it used to kill carried
// the light from the lit air), and never applies by day: the same values,
// bit for bit.  Its effect on the error is measured in bench convergence
// (docs/experiments/2026-11-22-path-tracer-variance.md), not here: a twilight path's relative std
// is about 7, so a sample variance is too noisy for an assertion.
TEST(IntegratorPhysics, ShadowRouletteThresholdKeepsTheMeanAndLeavesDaylightAlone) {
  IntegratorOptions low, one;
  low.rr_threshold_in_shadow = 0.25;
  one.rr_threshold_in_shadow = 1.0;
  const std::array<double, 4> lambdas = {430.0, 510.0, 590.0, 660.0};
  const Scene twilight =
      Scene::from_specs(AtmosphereSpec{}, sun_at(96.0, 0.0, 0.0), Location{}, std::nullopt, 400.0, 700.0);
  const VolumePathIntegrator a(twilight, low), b(twilight, one);
  PathCounters counters_a, counters_b;
  for (int d = 0; d < 5; ++d) {
    const Ray ray{twilight.observer(), direction_from_zenith_azimuth((20.0 + 30.0 * d) * kDegToRad, 0.7 * d)};
    const RotatedHeroMoments ma = radiance_with_rotated_hero(a, ray, lambdas, 8000, 41 + d);
    const RotatedHeroMoments mb = radiance_with_rotated_hero(b, ray, lambdas, 8000, 51 + d);
    counters_a.add(ma.counters);
    counters_b.add(mb.counters);
    for (std::size_t k = 0; k < 4; ++k)
      EXPECT_NEAR(ma.mean[k], mb.mean[k], 4.0 * std::hypot(ma.se[k], mb.se[k]))
          << "direction " << d << ", " << lambdas[k] << " nm";
  }
  EXPECT_EQ(counters_a.nonfinite + counters_b.nonfinite, 0u);
  EXPECT_GT(counters_a.collisions, counters_b.collisions * 11 / 10);

  const Scene noon = Scene::from_specs(AtmosphereSpec{}, sun_at(30.0, 0.0, 0.0), Location{}, std::nullopt, 400.0, 700.0);
  const VolumePathIntegrator c(noon, low), e(noon, one);
  const Ray ray{noon.observer(), direction_from_zenith_azimuth(70.0 * kDegToRad, 2.0)};
  const RotatedHeroMoments mc = radiance_with_rotated_hero(c, ray, lambdas, 2000, 7);
  const RotatedHeroMoments me = radiance_with_rotated_hero(e, ray, lambdas, 2000, 7);
  EXPECT_EQ(mc.mean, me.mean);
  EXPECT_EQ(mc.counters.collisions, me.counters.collisions);
}

// --- Shadow rays from the low, dense air are tracked against the residual of
// a control extinction (residual_tracking_below_altitude_m): the same mean,
// and less noise where the ground's sun NEE is most of the radiance (a view
// of the ground from 0 m at noon; measured: the relative standard errors at
// 430, 510, 590, 660 nm 0.0054, 0.0029, 0.0022, 0.0020 against 0.0073,
// 0.0035, 0.0050, 0.0071 with the rule off, a third of the variance).
TEST(IntegratorPhysics, LowShadowRaysByResidualTrackingKeepTheMeanWithLessNoise) {
  const Scene scene = Scene::from_specs(AtmosphereSpec{}, sun_at(30.0, 0.0, 0.0), Location{}, std::nullopt, 400.0, 700.0);
  IntegratorOptions low, off;
  off.residual_tracking_below_altitude_m = -1.0;
  const Ray ray{scene.observer(), direction_from_zenith_azimuth(120.0 * kDegToRad, 1.0)};
  const std::array<double, 4> lambdas = {430.0, 510.0, 590.0, 660.0};
  const RotatedHeroMoments a = radiance_with_rotated_hero(VolumePathIntegrator(scene, low), ray, lambdas, 8000, 61);
  const RotatedHeroMoments b = radiance_with_rotated_hero(VolumePathIntegrator(scene, off), ray, lambdas, 8000, 62);
  EXPECT_EQ(a.counters.nonfinite + b.counters.nonfinite, 0u);
  double var_a = 0.0, var_b = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(a.mean[k], b.mean[k], 4.0 * std::hypot(a.se[k], b.se[k])) << lambdas[k] << " nm";
    EXPECT_LT(a.se[k] / a.mean[k], b.se[k] / b.mean[k]) << lambdas[k] << " nm";
    var_a += sqr(a.se[k] / a.mean[k]);
    var_b += sqr(b.se[k] / b.mean[k]);
  }
  EXPECT_LT(var_a, 0.6 * var_b);
}

// --- Russian roulette with the LUT sky as a control variate
// (IntegratorOptions::roulette_control): the same means as plain roulette at
// 4 wavelengths in 4 directions of a noon sky (zenith 20, 60 and 85 deg, and
// the ground at 120 deg), every path's sum >= 0 (the firewall counts
// anything else), and less noise: the summed relative variance was 0.71-0.73
// of plain roulette's over 4 pairs of seeds.
TEST(IntegratorPhysics, RouletteControlKeepsTheMeanWithLessNoise) {
  const Scene scene = Scene::from_specs(AtmosphereSpec{}, sun_at(30.0, 0.0, 0.0), Location{}, std::nullopt, 400.0, 700.0);
  IntegratorOptions controlled, plain;
  controlled.roulette_control = std::make_shared<const RadianceControl>(scene);
  const VolumePathIntegrator a(scene, controlled), b(scene, plain);
  const std::array<double, 4> lambdas = {430.0, 510.0, 590.0, 660.0};
  double var_a = 0.0, var_b = 0.0;
  PathCounters counters;
  const std::array<double, 4> zeniths = {20.0, 60.0, 85.0, 120.0};
  for (std::size_t d = 0; d < zeniths.size(); ++d) {
    const Ray ray{scene.observer(), direction_from_zenith_azimuth(zeniths[d] * kDegToRad, 0.4 + 1.3 * d)};
    const RotatedHeroMoments ma = radiance_with_rotated_hero(a, ray, lambdas, 8000, 71 + d);
    const RotatedHeroMoments mb = radiance_with_rotated_hero(b, ray, lambdas, 8000, 81 + d);
    counters.add(ma.counters);
    counters.add(mb.counters);
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_NEAR(ma.mean[k], mb.mean[k], 4.0 * std::hypot(ma.se[k], mb.se[k]))
          << "zenith " << zeniths[d] << ", " << lambdas[k] << " nm";
      var_a += sqr(ma.se[k] / ma.mean[k]);
      var_b += sqr(mb.se[k] / mb.mean[k]);
    }
  }
  EXPECT_EQ(counters.nonfinite, 0u);
  EXPECT_LT(var_a, 0.8 * var_b);
}

// --- White furnace: a non-absorbing atmosphere over a white ground under a
// uniform sky light L_env (no sun) has radiance L_env everywhere, from any
// viewpoint, whatever the density profiles and phase functions (energy
// conservation).
TEST(IntegratorPhysics, WhiteFurnaceReturnsTheEnvironmentRadiance) {
  AtmosphereSpec spec;
  spec.preset = AtmospherePreset::kCustom;
  spec.ground_albedo = 1.0;
  ConstituentSpec air;
  air.name = "air";
  air.density = ExponentialDensity{8000.0};
  air.scattering_per_m = {{400.0, 700.0}, {3.0e-5, 6.0e-6}};
  air.phase = RayleighPhaseSpec{0.03};
  ConstituentSpec haze;
  haze.name = "haze";
  haze.density = ExponentialDensity{1200.0};
  haze.scattering_per_m = {{550.0}, {2e-4}};
  haze.phase = HenyeyGreensteinPhaseSpec{0.8};
  spec.constituents = {air, haze};
  for (double altitude : {0.0, 400000.0}) {
    Scene scene = Scene::from_specs(spec, sun_at(30.0, 0.0), Location{0, 0, altitude}, std::nullopt, 400.0, 700.0);
    scene.sun_enabled = false;
    scene.environment_radiance = 1.0;
    const std::vector<glm::dvec3> dirs = {direction_from_zenith_azimuth(0.0, 0.0),
                                          direction_from_zenith_azimuth(89.0 * kDegToRad, 1.0),
                                          direction_from_zenith_azimuth(120.0 * kDegToRad, 2.0),
                                          direction_from_zenith_azimuth(kPi, 0.0)};
    const ProbeResult r = probe_radiance(scene, dirs, {420.0, 650.0}, 4096, 3, 2);
    EXPECT_EQ(r.counters.nonfinite, 0u);
    EXPECT_EQ(r.counters.depth_limit, 0u);
    for (std::size_t d = 0; d < dirs.size(); ++d)
      for (std::size_t w = 0; w < 2; ++w)
        EXPECT_NEAR(r.radiance[d][w], 1.0, 4.0 * r.standard_error[d][w] + 1e-9)
            << "altitude " << altitude << " direction " << d << " wavelength " << w;
  }
}

// --- Azimuthal symmetry about the sun's vertical plane.
TEST(IntegratorPhysics, SkyIsMirrorSymmetricAboutTheSunsVerticalPlane) {
  AtmosphereSpec spec;  // earth with aerosols
  const Scene scene = Scene::from_specs(spec, sun_at(60.0, 100.0), Location{}, std::nullopt, 360.0, 830.0);
  std::vector<glm::dvec3> dirs;
  for (double dz : {20.0, 70.0, 88.0})
    for (double da : {-40.0, 40.0, -150.0, 150.0})
      dirs.push_back(direction_from_zenith_azimuth(dz * kDegToRad, (100.0 + da) * kDegToRad));
  const ProbeResult r = probe_radiance(scene, dirs, {450.0, 600.0}, 3000, 4, 2);
  for (std::size_t k = 0; k < dirs.size(); k += 2)
    for (std::size_t w = 0; w < 2; ++w) {
      const double a = r.radiance[k][w], b = r.radiance[k + 1][w];
      const double se = std::hypot(r.standard_error[k][w], r.standard_error[k + 1][w]);
      EXPECT_NEAR(a, b, 4.0 * se) << "pair " << k / 2 << " wavelength " << w;
      EXPECT_GT(a, 0.0);
    }
}

}  // namespace
}  // namespace skyfarm

namespace skyfarm {
namespace {

// --- Reciprocity (Chandrasekhar 1960, §17): for a horizontally uniform
// atmosphere over a black ground, the diffuse transmission function T in
//   L(mu, mu_0, dphi) = E mu_0 T(mu, mu_0, dphi) / pi
// is symmetric in (mu, mu_0).  So the sky radiance seen at zenith angle a with
// the sun at zenith angle b, divided by cos b, equals the radiance seen at b
// with the sun at a, divided by cos a (same relative azimuth).  On a sphere
// this holds to the curvature's order, well under the 1.5 % allowed here at
// 20-60 deg.
TEST(IntegratorPhysics, SkyRadianceIsReciprocalInViewAndSunZenith) {
  AtmosphereSpec spec;  // earth: air, ozone, aerosols
  spec.ground_albedo = 0.0;
  const double a = 20.0, b = 60.0, dphi = 70.0;
  auto radiance = [&](double view_zenith, double sun_zenith) {
    SunSpec sun = sun_at(sun_zenith, 0.0);
    const Scene scene = Scene::from_specs(spec, sun, Location{}, std::nullopt, 400.0, 700.0);
    const glm::dvec3 view = direction_from_zenith_azimuth(view_zenith * kDegToRad, dphi * kDegToRad);
    return probe_radiance(scene, {view}, {450.0, 650.0}, 60000, 13, 2);
  };
  const ProbeResult ab = radiance(a, b), ba = radiance(b, a);
  for (std::size_t w = 0; w < 2; ++w) {
    const double lhs = ab.radiance[0][w] / std::cos(b * kDegToRad);
    const double rhs = ba.radiance[0][w] / std::cos(a * kDegToRad);
    const double se = std::hypot(ab.standard_error[0][w] / std::cos(b * kDegToRad),
                                 ba.standard_error[0][w] / std::cos(a * kDegToRad));
    RecordProperty("relative_difference_" + std::to_string(w), std::to_string((lhs - rhs) / rhs));
    RecordProperty("relative_standard_error_" + std::to_string(w), std::to_string(se / rhs));
    EXPECT_NEAR(lhs, rhs, 4.0 * se + 0.015 * rhs) << "wavelength " << w;
  }
}

}  // namespace
}  // namespace skyfarm
