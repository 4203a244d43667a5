// LitDistanceSampler: the truncated-exponential distance pdf over the sunlit
// part of a segment integrates to 1 at every wavelength, is 0 in the shadow,
// and sample() inverts its CDF at the hero wavelength.
#include <gtest/gtest.h>

#include "tests/support/sun_specs.h"

#include <cmath>

#include "common/core/constants.h"
#include "common/core/integrate.h"
#include "common/geometry/sphere_intersection.h"
#include "common/render/lit_distance_sampler.h"
#include "common/render/scene.h"

namespace skyfarm {
namespace {

struct TwilightRay {
  Scene scene = Scene::from_specs(AtmosphereSpec{}, testing::sun_spec(96.0, 0.0), Location{}, std::nullopt, 360.0, 830.0);
  Ray ray{scene.observer(), direction_from_zenith_azimuth(80.0 * kDegToRad, 0.0)};  // towards the sun's azimuth
  double t1 = distance_to_sphere(ray, scene.atmosphere().top_radius_m());
  double R = scene.atmosphere().planet_radius_m();
  std::array<std::size_t, kWavelengthsPerPath> bins = scene.medium().bins([] {
    SampledWavelengths wl;
    wl.lambda_nm = {550.0, 400.0, 620.0, 800.0};
    wl.pdf.fill(1.0);
    return wl;
  }());
};

TEST(LitDistanceSampler, PdfIntegratesToOneOverTheLitPartAndIsZeroInTheShadow) {
  const TwilightRay r;
  const SunlitIntervals lit = sunlit_intervals(r.ray, 0.0, r.t1, r.scene.sun().direction(), r.R);
  ASSERT_TRUE(lit.shadowed);  // the observer is in the shadow at 96 deg
  ASSERT_GE(lit.count, 1);
  const LitDistanceSampler sampler(r.ray, lit, r.R, r.scene.medium().fine_shells(), r.bins);
  ASSERT_FALSE(sampler.empty());
  EXPECT_EQ(sampler.pdf(0.5 * lit.lit[0].first)[0], 0.0);  // in the shadow, before the lit part
  for (int i = 0; i < kWavelengthsPerPath; ++i) {
    double total = 0.0;
    for (int k = 0; k < lit.count; ++k)
      total += integrate_adaptive_simpson([&](double t) { return sampler.pdf(t)[i]; },
                                          lit.lit[static_cast<std::size_t>(k)].first,
                                          lit.lit[static_cast<std::size_t>(k)].second, 1e-9);
    EXPECT_NEAR(total, 1.0, 1e-4) << "wavelength slot " << i;
  }
}

TEST(LitDistanceSampler, SampleInvertsTheHerosCdf) {
  const TwilightRay r;
  const SunlitIntervals lit = sunlit_intervals(r.ray, 0.0, r.t1, r.scene.sun().direction(), r.R);
  const LitDistanceSampler sampler(r.ray, lit, r.R, r.scene.medium().fine_shells(), r.bins);
  for (double u : {0.1, 0.5, 0.9}) {
    double t = -1.0;
    ASSERT_TRUE(sampler.sample(u, &t));
    double cdf = 0.0;
    for (int k = 0; k < lit.count; ++k) {
      const auto [a, b] = lit.lit[static_cast<std::size_t>(k)];
      if (t > a) cdf += integrate_adaptive_simpson([&](double x) { return sampler.pdf(x)[0]; }, a, std::min(t, b), 1e-9);
    }
    EXPECT_NEAR(cdf, u, 1e-4) << "u " << u;
  }
}

}  // namespace
}  // namespace skyfarm
