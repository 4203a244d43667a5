// The ground under an observer at 0 m, pooled (render_plan.h
// "pooled_ground_row", common/film/ground_pool.h): which rows qualify, and
// a pooled render against the same render with every ground pixel traced.
#include <gtest/gtest.h>

#include <cmath>

#include "api/render_request.h"
#include "api/render_spec.h"
#include "common/render/local_render.h"

namespace skyfarm {
namespace {

TEST(GroundPoolPlan, RowsThatLookOnlyDownFromAnObserverOnTheGround) {
  CameraSpec cs;
  cs.width = 128;
  cs.height = 64;
  // Row 32 starts at the horizon (cos(pi / 2) rounds to +6e-17): not pooled.
  EXPECT_EQ(first_ground_row(cs), 33);
  const Camera camera(cs, {0.0, 0.0, 6371000.0});
  for (int y = 33; y < 64; y += 5)
    for (double j : {0.0, 0.5, 0.999999}) {
      Ray ray;
      ASSERT_TRUE(camera.generate_ray(7, y, j, j, &ray));
      EXPECT_LT(ray.d.z, 0.0) << y << " " << j;
    }
  Ray top_of_32;
  ASSERT_TRUE(camera.generate_ray(7, 32, 0.5, 0.0, &top_of_32));
  EXPECT_GE(top_of_32.d.z, 0.0);
  cs.pitch_deg = 1.0;
  EXPECT_EQ(first_ground_row(cs), -1);
  cs.pitch_deg = 0.0;
  cs.projection = Projection::kFisheye;
  EXPECT_EQ(first_ground_row(cs), -1);
  cs.projection = Projection::kEquirectangular;
  cs.height = 1;
  EXPECT_EQ(first_ground_row(cs), -1);

  const std::string body = R"({"sun": {"zenith_deg": 40, "azimuth_deg": 100},
    "camera": {"projection": "equirectangular", "width": 64, "height": 32}%s})";
  auto plan_of = [&](const std::string& extra) {
    std::string text = body;
    text.replace(text.find("%s"), 2, extra);
    const auto request = api::parse_render_request(text);
    return make_render_setup(api::render_spec(request)).plan;
  };
  EXPECT_EQ(plan_of("").pooled_ground_row, 17);
  EXPECT_EQ(plan_of(R"(, "location": {"altitude_m": 1})").pooled_ground_row, -1);
  EXPECT_EQ(plan_of(R"(, "method": "lut")").pooled_ground_row, -1);
}

TEST(GroundPoolPlan, APooledPixelTracesOneSamplePerPass) {
  RenderPlan plan = make_render_plan(64, 32, 360.0, 830.0, 1, 64, 1);
  plan.pooled_ground_row = 17;
  int first = 0, end = 0;
  plan.sample_range({0, 0, 2}, 3, 16, &first, &end);
  EXPECT_EQ(first, 32);
  EXPECT_EQ(end, 48);
  plan.sample_range({0, 0, 2}, 3, 17, &first, &end);
  EXPECT_EQ(first, 2);
  EXPECT_EQ(end, 3);
}

TEST(GroundPoolRender, PooledGroundAgreesWithTheTracedGroundAndTheSkyIsTheSameBits) {
  const auto request = api::parse_render_request(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 100},
    "camera": {"projection": "equirectangular", "width": 64, "height": 32},
    "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 64}})");
  const RenderSetup setup = make_render_setup(api::render_spec(request));
  ASSERT_EQ(setup.plan.pooled_ground_row, 17);
  const TileRenderer pooled_renderer(*setup.scene, *setup.camera, setup.plan);
  Image pooled(64, 32);
  const LocalRenderResult rp = render_image(pooled_renderer, &pooled, 2);

  RenderPlan traced_plan = setup.plan;
  traced_plan.pooled_ground_row = -1;
  const TileRenderer traced_renderer(*setup.scene, *setup.camera, traced_plan);
  Image traced(64, 32);
  const LocalRenderResult rt = render_image(traced_renderer, &traced, 2);
  EXPECT_EQ(rp.counters.nonfinite, 0u);
  // 15 rows of 64 trace 4 samples (one per pass) instead of 64.
  EXPECT_EQ(rt.counters.paths - rp.counters.paths, 15u * 64u * 60u);

  for (int y = 0; y < 17; ++y)
    for (int x = 0; x < 64; ++x) ASSERT_EQ(pooled.rgb(x, y), traced.rgb(x, y)) << x << "," << y;
  const double value = pooled.luminance(0, 17);
  double sum = 0.0, sum2 = 0.0;
  const int n = 15 * 64;
  for (int y = 17; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      ASSERT_EQ(pooled.rgb(x, y), pooled.rgb(0, 17)) << x << "," << y;
      const double Y = traced.luminance(x, y);
      sum += Y;
      sum2 += Y * Y;
    }
  // The traced ground's pixels are independent estimates of the same value:
  // their spread gives the standard error of their mean (64 samples each),
  // and of the pooled value (4 samples each, so 4x the error).
  const double mean = sum / n, sd = std::sqrt((sum2 / n - mean * mean) * n / (n - 1));
  const double se_traced = sd / std::sqrt(n), se_pooled = 4.0 * se_traced;
  EXPECT_GT(value, 0.0);
  EXPECT_NEAR(value, mean, 4.0 * std::hypot(se_traced, se_pooled)) << "relative se " << se_traced / mean;
  // What makes pooling exact: the traced ground is one value in every
  // direction, the rows just below the horizon (17-23) as the ones towards
  // the nadir (24-31) (a ray that missed the ground at the observer's feet
  // would meet it hundreds of km away, under another sun).
  double near = 0.0, down = 0.0;
  for (int x = 0; x < 64; ++x) {
    for (int y = 17; y < 24; ++y) near += traced.luminance(x, y) / (7 * 64);
    for (int y = 24; y < 32; ++y) down += traced.luminance(x, y) / (8 * 64);
  }
  EXPECT_NEAR(near, down, 4.0 * sd * std::sqrt(1.0 / (7 * 64) + 1.0 / (8 * 64)));
  // The pooled frame's estimate counts its ground pixels' variance as that of the pooled mean.
  ASSERT_TRUE(rp.estimate && rt.estimate);
  EXPECT_LT(*rp.estimate, *rt.estimate);
}

}  // namespace
}  // namespace skyfarm
