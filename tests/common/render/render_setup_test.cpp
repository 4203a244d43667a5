// The plan a render compiles to (common/render/render_setup.h
// render_plan_for): which renders get Russian roulette with the LUT sky as a
// control variate, and which the shadow guide.
#include "common/render/render_setup.h"

#include <gtest/gtest.h>

namespace skyfarm {
namespace {

// A small equirect view under the sun at `zenith_deg`, path traced or by the LUT renderer.
RenderPlan plan_of(double zenith_deg, bool lut = false) {
  RenderSpec spec;
  spec.sun.zenith_deg = zenith_deg;
  spec.sun.azimuth_deg = 180.0;
  spec.camera.projection = Projection::kEquirectangular;
  spec.camera.width = 64;
  spec.camera.height = 32;
  spec.lut = lut;
  return make_render_setup(spec).plan;
}

TEST(RenderPlanFor, RouletteControlOnlyForPathTracedSkiesWithAHighSun) {
  EXPECT_TRUE(plan_of(30.0).roulette_control);
  EXPECT_TRUE(plan_of(85.0).roulette_control);
  // A sun at the horizon or below: it no longer pays
  // (docs/experiments/2026-11-22-path-tracer-variance.md).
  EXPECT_FALSE(plan_of(90.0).roulette_control);
  EXPECT_FALSE(plan_of(96.0).roulette_control);
  // The LUT renderer traces no paths.
  EXPECT_FALSE(plan_of(30.0, true).roulette_control);
}

// The shadow guide (shadow_guide.h) for path-traced skies with the sun
// below the observer's horizon; at sunset it measured no gain.
TEST(RenderPlanFor, ShadowGuideOnlyForPathTracedSkiesWithTheSunBelowTheHorizon) {
  EXPECT_TRUE(plan_of(96.0).shadow_guide);
  EXPECT_TRUE(plan_of(108.0).shadow_guide);
  EXPECT_FALSE(plan_of(90.0).shadow_guide);
  EXPECT_FALSE(plan_of(30.0).shadow_guide);
  EXPECT_FALSE(plan_of(96.0, true).shadow_guide);
}

}  // namespace
}  // namespace skyfarm
