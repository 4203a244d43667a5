// The path tracer in clouds: Beer-Lambert, energy conservation in a
// conservative slab, and the extremes (thick clouds, the camera inside one,
// clouds lit from below at twilight, cirrus from geostationary orbit).
#include <gtest/gtest.h>

#include <cmath>

#include "common/core/constants.h"
#include "common/geometry/sphere_intersection.h"

#include "common/clouds/scene_clouds.h"
#include "common/clouds/uniform_cloud_slab.h"
#include "common/render/volume_path_integrator.h"
#include "tests/support/cloud_slab_scene.h"

namespace skyfarm {
namespace {

// --- Beer-Lambert: the transmittance towards the sun through a slab of
// vertical optical depth tau is exp(-tau / mu0), the air's (1e-15 m^-1 over
// 10 km) being 1 to 1e-11.  Ratio tracking with roulette is unbiased: its
// mean over many shadow rays matches within 4 standard errors.
TEST(CloudTransport, DirectSunThroughAThinCloudIsBeerLambert) {
  const double tau = 0.7, zenith = 50.0;
  const auto scene = testing::cloud_slab_scene(tau, testing::isotropic_cloud_optics(), zenith, 0.0);
  const VolumePathIntegrator integrator(*scene);
  SampledWavelengths wl;
  wl.lambda_nm.fill(550.0);
  wl.pdf.fill(1.0);
  PathCounters counters;
  const int n = 20000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(3, 0, static_cast<std::uint64_t>(i));
    const double T = integrator.transmittance(Ray{scene->observer(), scene->sun().direction()}, 1e7, wl, sampler,
                                              &counters)[0];
    sum += T;
    sum2 += T * T;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  // The slab is a shell: the exact chord replaces thickness / mu0.
  const double R = scene->atmosphere().planet_radius_m();
  const Ray up{scene->observer(), scene->sun().direction()};
  const double chord = distance_to_sphere(up, R + testing::kSlabTop_m) - distance_to_sphere(up, R + testing::kSlabBottom_m);
  const double exact = std::exp(-tau / (testing::kSlabTop_m - testing::kSlabBottom_m) * chord);
  // (The shell's curvature lengthens the chord by ~tan^2(zenith) h / R over the plane's.)
  EXPECT_NEAR(exact, std::exp(-tau / std::cos(zenith * kDegToRad)), 5e-4);
  EXPECT_NEAR(mean, exact, 4.0 * se);
  EXPECT_LT(se, 0.01);
}

// --- Conservation: albedo 1, black ground, no air: every photon that
// enters the slab leaves it up (R) or down (T), R + T_diffuse + T_direct = 1.
TEST(CloudTransport, ConservativeSlabReflectsPlusTransmitsEverything) {
  const double zenith = 30.0, mu0 = std::cos(zenith * kDegToRad);
  for (const double tau : {1.0, 10.0}) {
    for (const bool forward : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "tau " << tau << (forward ? " HG 0.85" : " isotropic"));
      const CloudOptics optics = forward ? testing::hg_cloud_optics(0.85) : testing::isotropic_cloud_optics();
      const auto above = testing::cloud_slab_scene(tau, optics, zenith, testing::kSlabTop_m + 1.0);
      const auto below = testing::cloud_slab_scene(tau, optics, zenith, testing::kSlabBottom_m - 1.0);
      // The forward peak makes the sun's NEE noisier: more paths.
      const int n = forward ? 24000 : 6000;
      const testing::FluxEstimate R = testing::hemisphere_flux_ratio(*above, false, n, 11);
      const testing::FluxEstimate T = testing::hemisphere_flux_ratio(*below, true, n, 12);
      const double direct = std::exp(-tau / mu0);
      EXPECT_EQ(R.counters.nonfinite + T.counters.nonfinite, 0u);
      EXPECT_EQ(R.counters.depth_limit + T.counters.depth_limit, 0u);
      const double se = std::hypot(R.se, T.se);
      EXPECT_NEAR(R.mean + T.mean + direct, 1.0, 4.0 * se + 2e-3) << "R " << R.mean << " T " << T.mean;
      EXPECT_LT(se, 0.02);
    }
  }
}

}  // namespace
}  // namespace skyfarm
