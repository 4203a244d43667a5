// The path tracer at the clouds' extremes, on uniform slabs over a black
// ground in an airless sky: a cloud of optical depth 500, the camera inside
// a cloud, a high cloud lit from beneath after sunset, cirrus seen from
// geostationary orbit.  Every estimate is finite and >= 0, no path reaches
// the depth cap, and the cost per path (tentative collisions, shadow rays
// included) stays bounded; the figures are printed for the experiments log.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "common/clouds/cloud_layer.h"
#include "common/core/constants.h"
#include "tests/support/cloud_slab_scene.h"

namespace skyfarm {
namespace {

struct Cost {
  testing::FluxEstimate flux;
  double collisions_per_path = 0.0;
};

Cost measure(const Scene& scene, bool looking_up, int n, std::uint64_t seed) {
  Cost c;
  c.flux = testing::hemisphere_flux_ratio(scene, looking_up, n, seed);
  c.collisions_per_path = static_cast<double>(c.flux.counters.collisions) / n;
  return c;
}

void expect_sane(const Cost& c, double max_collisions_per_path) {
  EXPECT_EQ(c.flux.counters.nonfinite, 0u);
  EXPECT_EQ(c.flux.counters.depth_limit, 0u);
  EXPECT_TRUE(std::isfinite(c.flux.mean));
  EXPECT_GE(c.flux.mean, 0.0);
  EXPECT_LT(c.collisions_per_path, max_collisions_per_path);
}

// tau 500 (a cumulonimbus' optical depth), g 0.85.  Seen from above nearly
// everything is reflected (diffusion theory: R = 1 - T, T ~ 1 / (0.75 tau
// (1 - g) + 1.42) ~ 0.018 for a conservative slab; Bohren 1987, "Multiple
// scattering of light and some of its observable consequences", Am. J.
// Phys. 55, 524).  The transmitted light needs walks of ~(tau (1 - g))^2 /
// (1 - g) ~ 40 000 scatterings, beyond the depth roulette's start (10 000):
// the estimate from below is unbiased but its mean lives in a heavy tail, and
// at a few thousand paths it reads low.  What must hold: finite, >= 0, no
// hard-cap hit, bounded collisions per path, and the reflectance.
TEST(CloudExtremes, OpticalDepth500IsFiniteAndBounded) {
  const auto above = testing::cloud_slab_scene(500.0, testing::hg_cloud_optics(0.85), 30.0, testing::kSlabTop_m + 1.0);
  const auto below = testing::cloud_slab_scene(500.0, testing::hg_cloud_optics(0.85), 30.0, testing::kSlabBottom_m - 1.0);
  const Cost R = measure(*above, false, 3000, 21);
  const Cost T = measure(*below, true, 1000, 22);
  std::printf("tau 500: R %.4f +- %.4f (%.0f collisions/path), T %.5f +- %.5f (%.0f collisions/path)\n",
              R.flux.mean, R.flux.se, R.collisions_per_path, T.flux.mean, T.flux.se, T.collisions_per_path);
  // Expected cost <= depth_rr_start + 1/(1 - survival) scatterings, each
  // with a shadow ray that roulette ends in a few collisions.
  expect_sane(R, 5000.0);
  expect_sane(T, 5000.0);
  EXPECT_NEAR(R.flux.mean, 0.982, 4.0 * R.flux.se + 0.01);
  EXPECT_LT(T.flux.mean, 0.05);
}

// The camera inside a cloud (fog): tau 50 over the 1 km slab, the camera in
// its middle looking up.  Finite, > 0, bounded.
TEST(CloudExtremes, CameraInsideACloudSeesFog) {
  const auto inside = testing::cloud_slab_scene(50.0, testing::hg_cloud_optics(0.85), 40.0, 1500.0);
  const Cost up = measure(*inside, true, 3000, 23);
  const Cost down = measure(*inside, false, 3000, 24);
  std::printf("inside tau 50: up %.4f (%.0f collisions/path), down %.4f (%.0f)\n", up.flux.mean,
              up.collisions_per_path, down.flux.mean, down.collisions_per_path);
  expect_sane(up, 20000.0);
  expect_sane(down, 20000.0);
  EXPECT_GT(up.flux.mean, 0.0);
  EXPECT_GT(down.flux.mean, 0.0);
  // More light above the camera than below it (the sun is above).
  EXPECT_GT(up.flux.mean, down.flux.mean);
}

// A broken cloud layer at 8.5-9.5 km after sunset, the sun 2.5 deg below
// the horizon: the planet's shadow covers the ground observer but not the
// clouds, which the sun lights from beneath through their gaps (a uniform
// shell could not be: the sun's ray from its base crosses the shell again
// far away).  The sky seen from the ground is lit.
TEST(CloudExtremes, SunBelowTheHorizonLightsCloudsFromBeneath) {
  auto scene = std::make_unique<Scene>(Scene::from_specs(testing::thin_hg_layer(1e-15, 10500.0, 0.0),
                                                         testing::sun_spec(92.5, 0.0, 0.0), Location{}, std::nullopt,
                                                         500.0, 600.0));
  CloudLayerSpec layer = cloud_layer_preset(CloudType::kCumulus);
  layer.base_m = 8500.0;
  layer.thickness_m = 1000.0;
  layer.coverage = 0.4;
  layer.optical_depth = 5.0;
  const double R = scene->atmosphere().planet_radius_m();
  scene->set_clouds(std::make_shared<SceneClouds>(
      std::vector<std::shared_ptr<const CloudField>>{std::make_shared<CloudLayer>(layer, R, glm::dvec3(0.0))}));
  const Cost up = measure(*scene, true, 40000, 25);
  std::printf("clouds lit from beneath: %.5f +- %.5f of mu0 E0 (%.1f collisions/path)\n", up.flux.mean, up.flux.se,
              up.collisions_per_path);
  expect_sane(up, 2000.0);
  EXPECT_GT(up.flux.mean, 4.0 * up.flux.se);
}

// Coverage 0 and 1 of a stratus layer at 1-2 km (tau 10 where full) over a
// black ground in an airless sky, point sun: with no cloud the sky seen
// from the ground is black (the point sun's direct beam is not a camera
// ray's to meet), with an overcast it is the cloud base's diffuse light.
TEST(CloudExtremes, CoverageZeroIsClearAndOneIsOvercast) {
  auto scene_with = [](double coverage) {
    auto scene = std::make_unique<Scene>(Scene::from_specs(testing::thin_hg_layer(1e-15, 10000.0, 0.0),
                                                           testing::sun_spec(40.0, 0.0, 0.0), Location{},
                                                           std::nullopt, 500.0, 600.0));
    CloudLayerSpec layer = cloud_layer_preset(CloudType::kStratus);
    layer.base_m = 1000.0;
    layer.thickness_m = 1000.0;
    layer.coverage = coverage;
    layer.optical_depth = 10.0;
    scene->set_clouds(std::make_shared<SceneClouds>(std::vector<std::shared_ptr<const CloudField>>{
        std::make_shared<CloudLayer>(layer, scene->atmosphere().planet_radius_m(), glm::dvec3(0.0))}));
    return scene;
  };
  const Cost clear = measure(*scene_with(0.0), true, 2000, 27);
  const Cost overcast = measure(*scene_with(1.0), true, 4000, 28);
  std::printf("coverage 0: %.5f (%.2f collisions/path); coverage 1: %.4f +- %.4f (%.0f collisions/path)\n",
              clear.flux.mean, clear.collisions_per_path, overcast.flux.mean, overcast.flux.se,
              overcast.collisions_per_path);
  expect_sane(clear, 4.0);  // the near-empty air's own tracking: ~2 per path
  expect_sane(overcast, 2000.0);
  EXPECT_LT(clear.flux.mean, 1e-9);  // (the 1e-15 m^-1 air's light: ~1e-11)
  EXPECT_GT(overcast.flux.mean, 4.0 * overcast.flux.se);
}

// Cirrus (tau 1, ice-like g 0.75) at 12-13 km seen from 36 000 km: rays
// start 36 000 km out, cross the shell and meet the slab; the lit cloud
// over a black ground reflects light back to space.
TEST(CloudExtremes, CirrusFromGeostationaryOrbit) {
  const auto scene = testing::cloud_slab_scene(1.0, testing::hg_cloud_optics(0.75), 30.0, 36.0e6, 12000.0, 13000.0);
  const VolumePathIntegrator integrator(*scene);
  SampledWavelengths wl;
  wl.lambda_nm.fill(testing::kSlabLambda_nm);
  wl.pdf.fill(1.0);
  PathCounters counters;
  double sum = 0.0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(26, 0, static_cast<std::uint64_t>(i));
    // Towards the sub-observer point, jittered over 1/100 rad (the disc is 0.18 rad across).
    const double dx = 0.01 * (sampler.get(1u << 30) - 0.5), dy = 0.01 * (sampler.get((1u << 30) + 1) - 0.5);
    const glm::dvec3 d = glm::normalize(glm::dvec3(dx, dy, -1.0));
    const double L = integrator.radiance(Ray{scene->observer(), d}, wl, sampler, &counters)[0];
    EXPECT_TRUE(std::isfinite(L));
    EXPECT_GE(L, 0.0);
    sum += L;
  }
  EXPECT_EQ(counters.nonfinite, 0u);
  EXPECT_EQ(counters.depth_limit, 0u);
  const double mean = sum / n * kPi / (std::cos(30.0 * kDegToRad) * scene->sun().irradiance(testing::kSlabLambda_nm));
  std::printf("cirrus from 36 000 km: pi L / (mu0 E0) = %.4f (%.1f collisions/path)\n", mean,
              static_cast<double>(counters.collisions) / n);
  // Single-scattering bound below, conservation above: 0 < R < 1.
  EXPECT_GT(mean, 0.01);
  EXPECT_LT(mean, 1.0);
}

}  // namespace
}  // namespace skyfarm
