// The measurement behind docs/experiments/2026-12-07-cloud-sun-lobe-sampling.md:
// the plane-parallel slab oracle's R and diffuse T (cloud_slab_scene.h)
// with the sun lobe at scatter_in_cloud off and at several probabilities,
// the same paths and seeds, against adding-doubling.  Disabled (it takes
// minutes); run it with
//   skyfarm_tests --gtest_also_run_disabled_tests --gtest_filter='*CloudSunLobeMeasurement*'
// It asserts nothing but finite results: the oracle tests assert.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "common/clouds/cloud_optics.h"
#include "common/core/constants.h"
#include "tests/support/adding_doubling.h"
#include "tests/support/cloud_slab_scene.h"

namespace skyfarm {
namespace {

struct Case {
  const char* name;
  CloudOptics optics;
  double tau, zenith_deg;
  int paths;
};

void measure(const Case& c, double lobe_probability) {
  const double mu0 = std::cos(c.zenith_deg * kDegToRad);
  const testing::SlabFluxes ad = testing::adding_doubling_slab(c.tau, c.optics.albedo, c.optics.phase, mu0, 48);
  const auto above = testing::cloud_slab_scene(c.tau, c.optics, c.zenith_deg, testing::kSlabTop_m + 1.0);
  const auto below = testing::cloud_slab_scene(c.tau, c.optics, c.zenith_deg, testing::kSlabBottom_m - 1.0);
  IntegratorOptions options;
  options.cloud_sun_lobe = lobe_probability > 0.0;
  auto start = std::chrono::steady_clock::now();
  const testing::FluxEstimate R = testing::hemisphere_flux_ratio(*above, false, c.paths, 21, options);
  const double t_R = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  start = std::chrono::steady_clock::now();
  const testing::FluxEstimate T = testing::hemisphere_flux_ratio(*below, true, c.paths, 22, options);
  const double t_T = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("| %s | %.0f | %.0f | %.1f | %d | %.4f +- %.4f (%.1f SE) | %.4f | %.4f +- %.4f (%.1f SE) | %.4f |"
              " %.0f / %.0f | %.2f / %.2f | %.3g / %.3g |\n",
              c.name, c.tau, c.zenith_deg, lobe_probability, c.paths, R.mean, R.se,
              (R.mean - ad.reflectance) / R.se, ad.reflectance, T.mean, T.se,
              (T.mean - ad.diffuse_transmittance) / T.se, ad.diffuse_transmittance,
              static_cast<double>(R.counters.collisions) / c.paths,
              static_cast<double>(T.counters.collisions) / c.paths, t_R, t_T, 1.0 / (R.se * R.se * t_R),
              1.0 / (T.se * T.se * t_T));
  std::fflush(stdout);
  EXPECT_TRUE(std::isfinite(R.mean) && std::isfinite(T.mean));
}

TEST(CloudSunLobeMeasurement, DISABLED_SlabOracleCases) {
  const CloudOptics mie = cloud_optics(CloudParticle::kWater, 10.0);
  const Case cases[] = {{"mie 10um", mie, 1.0, 30.0, 20000},
                        {"mie 10um", mie, 10.0, 30.0, 8000},
                        {"mie 10um", mie, 100.0, 60.0, 1000},
                        {"hg 0.85", testing::hg_cloud_optics(0.85), 10.0, 30.0, 8000}};
  std::printf("| phase | tau | sun zenith | lobe a | paths | R (PT) | R (AD) | T_diffuse (PT) | T_diffuse (AD) |"
              " collisions/path R / T | s R / T | 1/(SE^2 t) R / T |\n");
  for (const Case& c : cases)
    for (const double a : {0.0, 1.0}) measure(c, a);
}

}  // namespace
}  // namespace skyfarm
