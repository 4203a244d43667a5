// UnitResultCheck derives every pixel's sample count from the plan and the
// camera alone: a unit rendered by TileRenderer passes it exactly, including
// a fisheye's edge pixels (where jitter falls outside the circle), pixels
// outside the circle, pooled ground rows, adaptive counts and LUT units; one
// sample more or less anywhere does not.
#include "server/jobs/unit_result_check.h"

#include <gtest/gtest.h>

#include "api/render_spec.h"
#include "common/render/sample_allocation.h"
#include "common/render/tile_renderer.h"

namespace skyfarm::server {
namespace {

struct Rendered {
  RenderSetup setup;
  std::unique_ptr<TileRenderer> renderer;
  std::unique_ptr<UnitResultCheck> check;
  explicit Rendered(const char* request) : setup(make_render_setup(api::render_spec(api::parse_render_request(request)))) {
    renderer = std::make_unique<TileRenderer>(*setup.scene, *setup.camera, setup.plan);
    check = std::make_unique<UnitResultCheck>(setup.plan, *setup.camera, renderer->sun_pixels());
  }
  FilmTile render(const WorkUnit& u) const {
    FilmTile film = renderer->empty_tile(u.tile);
    PathCounters counters;
    renderer->render_unit(u, &film, &counters);
    return film;
  }
};

// Every unit of pass p passes, and each pixel's count is the expected one;
// returns how many pixels had fewer samples than the pass's full count but more than none.
int expect_pass_accepted(const Rendered& r, int pass, std::vector<PassSamples> samples = {}) {
  int partial = 0;
  const RenderPlan& plan = r.setup.plan;
  for (int t = 0; t < plan.tile_count(); ++t) {
    for (int b = 0; b < plan.batches; ++b) {
      WorkUnit u{t, b, pass, samples};
      const FilmTile film = r.render(u);
      EXPECT_EQ(r.check->check(u, film), "") << "tile " << t << " batch " << b << " pass " << pass;
      for (int y = film.y0(); y < film.y0() + film.height(); ++y)
        for (int x = film.x0(); x < film.x0() + film.width(); ++x) {
          const int n = static_cast<int>(film.sums(x, y, b).n);
          EXPECT_EQ(n, r.check->expected_samples(u, x, y)) << x << ", " << y;
          int first = 0, end = 0;
          plan.sample_range(u, x, y, &first, &end);
          if (n > 0 && n < end - first) ++partial;
        }
    }
  }
  return partial;
}

TEST(UnitResultCheck, FisheyeEdgePixelsAndPixelsOutsideTheCircle) {
  const Rendered r(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 100},
    "camera": {"projection": "fisheye", "width": 24, "height": 24, "pitch_deg": 90, "fov_deg": 180},
    "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 16}, "seed": 4})");
  EXPECT_GT(expect_pass_accepted(r, 0), 0) << "some edge pixels lose samples outside the circle";
  // A pixel outside the circle (a corner) has none.
  EXPECT_EQ(r.check->expected_samples({0, 0, 0}, 0, 0), 0);
}

TEST(UnitResultCheck, PooledGroundRowsAndAShortLastPass) {
  const Rendered r(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 100},
    "camera": {"projection": "equirectangular", "width": 32, "height": 16},
    "quality": {"samples_per_pixel": 20}, "seed": 5})");
  ASSERT_GE(r.setup.plan.pooled_ground_row, 0);
  expect_pass_accepted(r, 0);
  expect_pass_accepted(r, 1);  // 4 samples, the ground's one
  EXPECT_EQ(r.check->expected_samples({0, 0, 1}, 3, 15), 1);
  EXPECT_EQ(r.check->expected_samples({0, 0, 1}, 3, 2), 4);
}

TEST(UnitResultCheck, AdaptiveCountsPerBlockAndParity) {
  const Rendered r(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 100},
    "camera": {"projection": "perspective", "width": 16, "height": 16, "pitch_deg": 30},
    "quality": {"samples_per_pixel": 48, "adaptive": true}, "seed": 6})");
  ASSERT_TRUE(r.setup.plan.adaptive);
  std::vector<PassSamples> samples(static_cast<std::size_t>(r.setup.plan.block_count(0)));
  for (std::size_t i = 0; i < samples.size(); ++i) samples[i] = {static_cast<int>(i) + 1, 2 * static_cast<int>(i) + 3};
  expect_pass_accepted(r, 1, samples);
  EXPECT_EQ(r.check->expected_samples({0, 0, 1, samples}, 0, 0), 1);   // block 0, even
  EXPECT_EQ(r.check->expected_samples({0, 0, 1, samples}, 9, 0), 5);   // block 1, odd
}

TEST(UnitResultCheck, LutUnitsOfAFisheye) {
  const Rendered r(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 100},
    "camera": {"projection": "fisheye", "width": 24, "height": 24, "pitch_deg": 90, "fov_deg": 180},
    "spectral": {"batches": 2}, "method": "lut"})");
  expect_pass_accepted(r, 0);
}

TEST(UnitResultCheck, OneSampleMoreOrLessOrAWrongShapeIsRefused) {
  const Rendered r(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 100},
    "camera": {"projection": "equirectangular", "width": 40, "height": 20},
    "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 16}, "seed": 7})");
  const WorkUnit u{1, 1, 0};
  const FilmTile good = r.render(u);
  ASSERT_EQ(r.check->check(u, good), "");
  EXPECT_NE(r.check->check({1, 0, 0}, good), "") << "the samples are in another batch than asked";
  EXPECT_NE(r.check->check({0, 1, 0}, good), "") << "another tile";
  for (double delta : {-1.0, 1.0}) {
    FilmTile bad = good;
    PixelBatchSums s = bad.sums(35, 7, 1);
    s.n += delta;
    bad.set_sums(35, 7, 1, s);
    const std::string why = r.check->check(u, bad);
    EXPECT_NE(why.find("pixel (35, 7) of batch 1"), std::string::npos) << why;
  }
  FilmTile narrow(good.x0(), good.y0(), good.width() - 1, good.height(), good.batches());
  EXPECT_NE(r.check->check(u, narrow).find("tile 1 is 8 x 20"), std::string::npos) << r.check->check(u, narrow);
}

}  // namespace
}  // namespace skyfarm::server
