// The scene plan a request compiles to (api/render_setup.h render_plan_for):
// which renders get Russian roulette with the LUT sky as a control variate,
// and which the shadow guide.
#include <gtest/gtest.h>

#include <string>

#include "api/render_request.h"
#include "api/render_setup.h"

namespace skyfarm::api {
namespace {

// A small equirect view under the sun at `zenith_deg`, rendered by `method`.
RenderPlan plan_of(double zenith_deg, const char* method = "path") {
  const std::string json = std::string(R"({"sun": {"zenith_deg": )") + std::to_string(zenith_deg) +
                           R"(, "azimuth_deg": 180}, "camera": {"projection": "equirectangular", "width": 64, "height": 32},
                              "method": ")" + method + "\"}";
  return make_render_setup(parse_render_request(json)).plan;
}

TEST(RenderPlanFor, RouletteControlOnlyForPathTracedSkiesWithAHighSun) {
  EXPECT_TRUE(plan_of(30.0).roulette_control);
  EXPECT_TRUE(plan_of(85.0).roulette_control);
  // A sun at the horizon or below: it no longer pays
  // (docs/experiments/2026-11-22-path-tracer-variance.md).
  EXPECT_FALSE(plan_of(90.0).roulette_control);
  EXPECT_FALSE(plan_of(96.0).roulette_control);
  // The LUT renderer traces no paths.
  EXPECT_FALSE(plan_of(30.0, "lut").roulette_control);
}

// The shadow guide (shadow_guide.h) for path-traced skies with the sun
// below the observer's horizon; at sunset it measured no gain.
TEST(RenderPlanFor, ShadowGuideOnlyForPathTracedSkiesWithTheSunBelowTheHorizon) {
  EXPECT_TRUE(plan_of(96.0).shadow_guide);
  EXPECT_TRUE(plan_of(108.0).shadow_guide);
  EXPECT_FALSE(plan_of(90.0).shadow_guide);
  EXPECT_FALSE(plan_of(30.0).shadow_guide);
  EXPECT_FALSE(plan_of(96.0, "lut").shadow_guide);
}

}  // namespace
}  // namespace skyfarm::api
