// The production path tracer (VolumePathIntegrator, every variance-reduction
// device on or off) against a naive oracle that shares none of them
// (tests/support/naive_sky_estimator.h: analog free flight by step
// quadrature, analog absorption, phase-function sampling, sun NEE with
// quadrature transmittance), in the default Earth atmosphere at twilight,
// where the devices matter most; and the first order against a
// deterministic quadrature of the single-scattering integral.
//
// Agreement: |a - b| < 4 sqrt(se_a^2 + se_b^2) + floor * max(a, b).  The
// floor (0.3 %) covers the oracle's deterministic errors: its altitude table
// (~2e-6) and midpoint quadratures (< 1e-4 of an optical depth of up to ~30
// along grazing shadow rays: ~0.3 % of a transmittance).  Measurements:
// docs/experiments/2026-12-07-naive-oracle.md.
#include <gtest/gtest.h>

#include "tests/support/naive_sky_estimator.h"
#include "tests/support/sun_specs.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "common/core/constants.h"
#include "common/render/radiance_control.h"
#include "common/render/shadow_guide.h"
#include "common/render/volume_path_integrator.h"

namespace skyfarm {
namespace {

using testing::NaiveEstimate;
using testing::NaiveSkyEstimator;

constexpr double kFloor = 0.003;

Scene twilight_scene(double sun_zenith_deg, double sun_radius_deg = 0.2666) {
  return Scene::from_specs(AtmosphereSpec{}, testing::sun_spec(sun_zenith_deg, 0.0, sun_radius_deg), Location{},
                           std::nullopt, 400.0, 700.0);
}

Ray view_ray(const Scene& scene, double zenith_deg) {
  // Azimuth 0: towards the sun's.
  return Ray{scene.observer(), direction_from_zenith_azimuth(zenith_deg * kDegToRad, 0.0)};
}

// The production estimator at one wavelength (all four slots at lambda, so
// spectral MIS is the identity) over `paths` paths.
NaiveEstimate production(const Scene& scene, const IntegratorOptions& options, const Ray& ray, double lambda,
                         int paths, std::uint64_t seed, PathCounters* counters) {
  const VolumePathIntegrator integrator(scene, options);
  SampledWavelengths wl;
  wl.lambda_nm.fill(lambda);
  wl.pdf.fill(1.0);
  return testing::estimate_mean(paths, [&](int i) {
    Sampler sampler(seed, 0, static_cast<std::uint64_t>(i));
    return integrator.radiance(ray, wl, sampler, counters)[0];
  });
}

void expect_agree(const NaiveEstimate& a, const NaiveEstimate& b, const std::string& what) {
  const double bound = 4.0 * std::hypot(a.standard_error, b.standard_error) + kFloor * std::max(a.mean, b.mean);
  EXPECT_NEAR(a.mean, b.mean, bound) << what << ": production " << a.mean << " +- " << a.standard_error
                                     << ", naive " << b.mean << " +- " << b.standard_error;
  std::printf("%-60s prod %.6e +- %.2e (%.2fs)  naive %.6e +- %.2e (%.2fs)  z %.2f\n", what.c_str(), a.mean,
              a.standard_error, a.seconds, b.mean, b.standard_error, b.seconds,
              (a.mean - b.mean) / std::hypot(a.standard_error, b.standard_error));
}

// The oracle's analog walk limited to one order against its own quadrature
// (point sun): a check of the oracle's free flight, collision choice and NEE
// against the integral they estimate, at sunset and in twilight.
TEST(NaiveOracle, OracleWalkMatchesItsSingleScatteringQuadrature) {
  for (double sun_zenith : {90.0, 96.0}) {
    const Scene scene = twilight_scene(sun_zenith, 0.0);
    const NaiveSkyEstimator naive(scene, 650.0);
    const Ray ray = view_ray(scene, 85.0);
    NaiveEstimate quadrature;
    quadrature.mean = naive.single_scattering(ray);
    ASSERT_GT(quadrature.mean, 0.0);
    const NaiveEstimate walk = naive.estimate(ray, 40000, 11, 1);
    expect_agree(walk, quadrature, "oracle walk vs quadrature, sun " + std::to_string(sun_zenith));
    EXPECT_LT(walk.standard_error, 0.1 * quadrature.mean);  // sharp enough to see a 40 % error
  }
}

// The production estimator limited to one scattering event (max_depth 1),
// point sun, against the deterministic single-scattering integral, with
// both of its first-order estimators (NEE at tentative collisions with
// forced collisions, and the sunlit-segment estimator) and the twilight
// rule on and off: the planet's shadow cuts the view ray at 93 and 96 deg.
TEST(NaiveOracle, SingleScatteringMatchesQuadrature) {
  struct Variant {
    const char* name;
    bool explicit_single, sunlit_in_shadow;
  };
  const Variant variants[] = {{"default", false, true}, {"explicit", true, true}, {"no lit segments", false, false}};
  for (double sun_zenith : {90.0, 93.0, 96.0, 100.0}) {
    const Scene scene = twilight_scene(sun_zenith, 0.0);
    for (double lambda : {450.0, 650.0}) {
      const NaiveSkyEstimator naive(scene, lambda);
      for (double view_zenith : {0.0, 85.0}) {
        const Ray ray = view_ray(scene, view_zenith);
        NaiveEstimate q;
        q.mean = naive.single_scattering(ray);
        for (const Variant& v : variants) {
          // Without the sunlit-segment estimator at 100 deg the lit air
          // (above ~60 km along the view) is hardly ever reached by a
          // collision: 0 of 8000 paths score; at 10^6 paths it agreed
          // (z 0.87, SE 18 %; the experiment log).
          if (sun_zenith >= 100.0 && !v.sunlit_in_shadow) continue;
          IntegratorOptions options;
          options.max_depth = 1;
          options.explicit_single_scattering = v.explicit_single;
          options.sunlit_segments_in_shadow = v.sunlit_in_shadow;
          PathCounters counters;
          const NaiveEstimate p = production(scene, options, ray, lambda, 8000, 5, &counters);
          EXPECT_EQ(counters.nonfinite, 0u);
          expect_agree(p, q,
                       "single sun " + std::to_string(sun_zenith) + " " + std::to_string(lambda) + " nm view " +
                           std::to_string(view_zenith) + " " + v.name);
        }
      }
    }
  }
}

// One case of the table: production (default options) against the oracle.
void compare_case(double sun_zenith, double lambda, double view_zenith, int production_paths, int naive_paths) {
  const Scene scene = twilight_scene(sun_zenith);
  const Ray ray = view_ray(scene, view_zenith);
  PathCounters counters;
  const NaiveEstimate p = production(scene, IntegratorOptions{}, ray, lambda, production_paths, 3, &counters);
  const NaiveEstimate n = NaiveSkyEstimator(scene, lambda).estimate(ray, naive_paths, 4);
  EXPECT_EQ(counters.nonfinite, 0u);
  EXPECT_EQ(counters.depth_limit, 0u);
  EXPECT_GT(n.mean, 0.0);
  expect_agree(p, n,
               "all orders sun " + std::to_string(sun_zenith) + " " + std::to_string(lambda) + " nm view " +
                   std::to_string(view_zenith));
}

// All orders, default options: the representative subset (sun 93 deg, both
// wavelengths, zenith and towards the sun's horizon; 96 deg towards the
// sun's horizon, where the oracle is still sharp enough at 50000 paths).
TEST(NaiveOracle, AllOrdersAgreeAtTwilight) {
  for (double lambda : {450.0, 650.0}) {
    for (double view_zenith : {0.0, 85.0}) compare_case(93.0, lambda, view_zenith, 8000, 50000);
    compare_case(96.0, lambda, 85.0, 8000, 50000);
  }
}

// The whole table (sun 90, 93, 96, 100 deg x 450, 650 nm x zenith, horizon):
// a manual run (--gtest_also_run_disabled_tests), its figures in the log.
// Not at sun 100 deg, view zenith: there the lit air is reached only by
// long multiple-scattering paths, and the oracle's 100000 paths score not
// once (its estimate is 0; the production's 2.3e-7 at 450 nm).
TEST(NaiveOracle, DISABLED_AllOrdersFullTable) {
  for (double sun_zenith : {90.0, 93.0, 96.0, 100.0})
    for (double lambda : {450.0, 650.0})
      for (double view_zenith : {0.0, 85.0})
        if (sun_zenith < 100.0 || view_zenith > 0.0) compare_case(sun_zenith, lambda, view_zenith, 20000, 100000);
}

// Every IntegratorOptions setting that changes the estimator but not its
// expectation, each toggled from the default, against one oracle estimate
// per case, towards the sun's azimuth at 85 deg: sun 93 deg at 450 nm (the
// observer in the planet's shadow, so every twilight device plays; the
// oracle's SE ~3 %) and sun 96 deg at 650 nm (deeper twilight; SE ~4 %).
// Options without effect here: surface_sun_sampling and
// surface_mis_heuristic (material grounds and objects only; the default
// ground is Lambertian), cloud_sun_lobe (clouds only), max_depth (a cost cap,
// not an unbiased device).
void compare_toggles(double sun_zenith, double lambda, std::uint64_t naive_seed, std::uint64_t production_seed) {
  const Scene scene = twilight_scene(sun_zenith);
  const Ray ray = view_ray(scene, 85.0);
  const NaiveEstimate n = NaiveSkyEstimator(scene, lambda).estimate(ray, 100000, naive_seed);
  struct Toggle {
    std::string name;
    IntegratorOptions options;
  };
  std::vector<Toggle> toggles;
  const auto add = [&](std::string name, auto&& edit) {
    IntegratorOptions o;
    edit(o);
    toggles.push_back({std::move(name), o});
  };
  add("default", [](IntegratorOptions&) {});
  add("rr_start_depth 1000 (no throughput roulette)", [](IntegratorOptions& o) { o.rr_start_depth = 1000; });
  add("rr_threshold_in_shadow 1", [](IntegratorOptions& o) { o.rr_threshold_in_shadow = 1.0; });
  add("depth roulette from depth 2, survival 0.8", [](IntegratorOptions& o) {
    o.depth_rr_start = 2;
    o.depth_rr_survival = 0.8;
  });
  add("camera majorant inflation x8, 4 collisions", [](IntegratorOptions& o) {
    o.camera_target_collisions = 4.0;
    o.max_camera_majorant_scale = 8.0;
  });
  add("shadow_majorant_scale 1, no residual tracking", [](IntegratorOptions& o) {
    o.residual_ratio_tracking = false;
    o.shadow_majorant_scale = 1.0;
  });
  add("residual tracking on every shadow ray", [](IntegratorOptions& o) {
    o.residual_tracking_below_cos = 2.0;
    o.residual_tracking_below_altitude_m = 1e9;
  });
  add("explicit_single_scattering on", [](IntegratorOptions& o) { o.explicit_single_scattering = true; });
  add("sunlit_segments_in_shadow off", [](IntegratorOptions& o) { o.sunlit_segments_in_shadow = false; });
  add("twilight_guide_fraction 0", [](IntegratorOptions& o) { o.twilight_guide_fraction = 0.0; });
  add("forced_collision_segments 0", [](IntegratorOptions& o) { o.forced_collision_segments = 0; });
  add("shadow_guide on", [&](IntegratorOptions& o) { o.shadow_guide = std::make_shared<const ShadowGuide>(scene); });
  add("roulette_control on", [&](IntegratorOptions& o) {
    o.roulette_control = std::make_shared<const RadianceControl>(scene);
  });
  const std::string where = "sun " + std::to_string(sun_zenith) + " " + std::to_string(lambda) + " nm: ";
  for (const Toggle& t : toggles) {
    PathCounters counters;
    const NaiveEstimate p = production(scene, t.options, ray, lambda, 4000, ++production_seed, &counters);
    EXPECT_EQ(counters.nonfinite, 0u) << where << t.name;
    expect_agree(p, n, where + t.name);
  }
}

TEST(NaiveOracle, EveryDeviceToggledAgreesWithTheOracle) {
  compare_toggles(93.0, 450.0, 8, 100);
  compare_toggles(96.0, 650.0, 9, 200);
}

}  // namespace
}  // namespace skyfarm
