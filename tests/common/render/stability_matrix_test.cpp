// The stability matrix: sun zenith 0 ... 108 deg x
// camera at 0 m ... geostationary orbit, equirectangular views: every pixel
// finite and >= 0, no path rejected by the NaN/Inf firewall, none cut by the
// depth cap; and at sun zenith 96 deg the sky towards the sun is dim but not
// black (light scattered high in the atmosphere, Earth's shadow below).
#include <gtest/gtest.h>

#include <cmath>

#include "common/core/constants.h"
#include "common/render/local_render.h"
#include "common/render/radiance_probe.h"

namespace skyfarm {
namespace {

TEST(StabilityMatrix, EveryPixelFiniteAndNonNegative) {
  const double sun_zeniths[] = {0.0, 60.0, 85.0, 89.0, 90.0, 92.0, 96.0, 108.0};
  const double altitudes[] = {0.0, 2000.0, 10000.0, 100000.0, 36000000.0};
  for (double sz : sun_zeniths) {
    for (double alt : altitudes) {
      SCOPED_TRACE("sun zenith " + std::to_string(sz) + ", camera at " + std::to_string(alt) + " m");
      AtmosphereSpec atmosphere;  // earth with aerosols
      SunSpec sun;
      sun.zenith_deg = sz;
      sun.azimuth_deg = 120.0;
      const Scene scene = Scene::from_specs(atmosphere, sun, Location{0, 0, alt}, std::nullopt, 360.0, 830.0);
      // Equirectangular views everywhere; from 100 km up also a perspective
      // view straight down at the planet and its limb.
      std::vector<CameraSpec> cameras(1);
      cameras[0].width = 24;
      cameras[0].height = 12;
      if (alt >= 100000.0) {
        CameraSpec down = cameras[0];
        down.projection = Projection::kPerspective;
        down.pitch_deg = -90.0;
        down.fov_deg = alt > 1e6 ? 20.0 : 150.0;
        cameras.push_back(down);
      }
      for (const CameraSpec& cs : cameras) {
        const Camera camera(cs, scene.observer());
        const RenderPlan plan = make_render_plan(cs.width, cs.height, 360.0, 830.0, 2, 2, 7, 12, 2);
        const TileRenderer renderer(scene, camera, plan);
        Image image(cs.width, cs.height);
        const LocalRenderResult r = render_image(renderer, &image, 2);
        EXPECT_EQ(r.counters.nonfinite, 0u);
        EXPECT_EQ(r.counters.depth_limit, 0u);
        double sum = 0.0;
        for (int y = 0; y < cs.height; ++y)
          for (int x = 0; x < cs.width; ++x) {
            const auto rgb = image.rgb(x, y);
            const double Y = image.luminance(x, y);
            ASSERT_TRUE(std::isfinite(Y) && Y >= 0.0) << x << "," << y;
            for (float c : rgb) ASSERT_TRUE(std::isfinite(c)) << x << "," << y;
            sum += Y;
          }
        if (sz <= 90.0) {
          EXPECT_GT(sum, 0.0) << "a sunlit view is not black";
        }
      }
    }
  }
}

TEST(StabilityMatrix, TwilightSkyTowardsTheSunIsDimButNotBlack) {
  AtmosphereSpec atmosphere;
  SunSpec sun;
  sun.zenith_deg = 96.0;
  sun.azimuth_deg = 270.0;
  const Scene scene = Scene::from_specs(atmosphere, sun, Location{}, std::nullopt, 360.0, 830.0);
  const std::vector<glm::dvec3> dirs = {direction_from_zenith_azimuth(80.0 * kDegToRad, 270.0 * kDegToRad),
                                        direction_from_zenith_azimuth(80.0 * kDegToRad, 90.0 * kDegToRad)};
  const ProbeResult r = probe_radiance(scene, dirs, {450.0, 600.0}, 40000, 11, 2);
  const ProbeResult noon =
      probe_radiance(Scene::from_specs(atmosphere, [] {
                       SunSpec s;
                       s.zenith_deg = 30.0;
                       s.azimuth_deg = 270.0;
                       return s;
                     }(), Location{}, std::nullopt, 360.0, 830.0),
                     {dirs[0]}, {450.0, 600.0}, 2000, 11, 2);
  for (std::size_t w = 0; w < 2; ++w) {
    const double towards = r.radiance[0][w], away = r.radiance[1][w];
    EXPECT_GT(towards, 4.0 * r.standard_error[0][w]) << "not black towards the sun";
    EXPECT_LT(towards, 0.05 * noon.radiance[0][w]) << "dim compared with day";
    EXPECT_GT(towards, away) << "brighter towards the sun than away from it";
  }
  EXPECT_EQ(r.counters.nonfinite, 0u);
}

}  // namespace
}  // namespace skyfarm
