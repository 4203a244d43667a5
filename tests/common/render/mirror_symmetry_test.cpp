// Mirror symmetry: an equirectangular view centred
// on the sun's vertical plane renders its left half and mirrors it.
#include <gtest/gtest.h>

#include <cmath>

#include "api/render_spec.h"
#include "common/render/local_render.h"

namespace skyfarm {
namespace {

TEST(MirrorSymmetry, ChosenOnlyWhenTheViewIsSymmetric) {
  CameraSpec cs;
  cs.width = 128;
  cs.height = 64;
  cs.yaw_deg = 135.0;
  EXPECT_TRUE(mirror_symmetric(cs, 135.0));
  EXPECT_TRUE(mirror_symmetric(cs, 315.0));   // looking away from the sun
  EXPECT_FALSE(mirror_symmetric(cs, 136.0));
  cs.pitch_deg = 5.0;
  EXPECT_FALSE(mirror_symmetric(cs, 135.0));
  cs.pitch_deg = 0.0;
  cs.width = 96;  // not whole pairs of 32-pixel tiles
  EXPECT_FALSE(mirror_symmetric(cs, 135.0));
  cs.width = 128;
  cs.projection = Projection::kFisheye;
  EXPECT_FALSE(mirror_symmetric(cs, 135.0));
}

TEST(MirrorSymmetry, HalfRenderedHalfMirroredAndPhysicallyRight) {
  const auto request = api::parse_render_request(R"({"sun": {"zenith_deg": 60, "azimuth_deg": 135},
    "camera": {"projection": "equirectangular", "width": 128, "height": 64, "yaw_deg": 135},
    "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 32}})");
  const RenderSetup setup = make_render_setup(api::render_spec(request));
  ASSERT_TRUE(setup.plan.mirrored);
  EXPECT_EQ(setup.plan.tile_count(), 2 * 2);  // the left 64 columns only
  const TileRenderer half(*setup.scene, *setup.camera, setup.plan);
  Image mirrored(128, 64);
  const LocalRenderResult rm = render_image(half, &mirrored, 2);

  RenderPlan full_plan = make_render_plan(128, 64, 360.0, 830.0, 1, 32, 1);
  full_plan.roulette_control = setup.plan.roulette_control;  // the same estimator
  full_plan.pooled_ground_row = setup.plan.pooled_ground_row;  // and the same pooled ground
  ASSERT_FALSE(full_plan.mirrored);
  const TileRenderer full(*setup.scene, *setup.camera, full_plan);
  Image reference(128, 64);
  const LocalRenderResult rf = render_image(full, &reference, 2);
  EXPECT_LT(rm.counters.paths * 10, rf.counters.paths * 6) << "about half the paths";

  // The sun (zenith 60 deg, at the view's centre) sits on the column
  // boundary at about row 21: its pixels, a few sun-disk hits each at
  // 32 spp, are left out of the comparison of the halves.
  const auto near_sun = [](int x, int y) { return x >= 60 && std::abs(y - 21) <= 3; };
  double left = 0.0, right_mirrored = 0.0, right_rendered = 0.0;
  // The observer is at 0 m: rows 33-63 see only the ground at its feet and
  // are pooled (ground_pool.h), over the left half's pixels in one frame and
  // over all of them in the other, so they are the same value in each frame.
  const int ground = setup.plan.pooled_ground_row;
  ASSERT_EQ(ground, 33);
  EXPECT_NEAR(mirrored.luminance(0, ground) / reference.luminance(0, ground), 1.0, 0.02);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      // Left half: the same units, the same bits (the pooled ground: one value).
      if (y < ground)
        ASSERT_EQ(mirrored.rgb(x, y), reference.rgb(x, y)) << x << "," << y;
      else
        ASSERT_EQ(mirrored.rgb(x, y), mirrored.rgb(0, ground)) << x << "," << y;
      // Right half: the exact mirror image.
      ASSERT_EQ(mirrored.rgb(127 - x, y), mirrored.rgb(x, y));
      if (near_sun(x, y) || y >= ground) continue;  // the sky: the ground is pooled per frame
      left += reference.luminance(x, y);
      right_mirrored += mirrored.luminance(127 - x, y);
      right_rendered += reference.luminance(127 - x, y);
    }
  EXPECT_EQ(left, right_mirrored);
  // Rendered for real, the right half has the same sky (away from the noisy
  // sun pixels, the totals agree to a few percent at 32 spp).
  EXPECT_NEAR(right_rendered / left, 1.0, 0.1);
}

}  // namespace
}  // namespace skyfarm
