// Determinism: every random number is a pure function of (seed,
// pixel, sample, dimension), so a tile rendered twice, or its units rendered
// one by one in any order and merged in the plan's order, or an image rendered
// with any number of threads, gives bit-identical sums.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <vector>

#include "common/render/local_render.h"
#include "common/render/tile_renderer.h"

namespace skyfarm {
namespace {

struct Fixture {
  Scene scene;
  Camera camera;
  RenderPlan plan;
};

Fixture make_fixture(int width, int height, int spp) {
  AtmosphereSpec atmosphere;  // earth, with aerosols
  SunSpec sun;
  sun.zenith_deg = 70.0;
  sun.azimuth_deg = 250.0;
  Scene scene = Scene::from_specs(atmosphere, sun, Location{0, 0, 300.0}, std::nullopt, 360.0, 830.0);
  CameraSpec cs;
  cs.projection = Projection::kEquirectangular;
  cs.width = width;
  cs.height = height;
  Camera camera(cs, scene.observer());
  RenderPlan plan = make_render_plan(width, height, 360.0, 830.0, 4, spp, 99, 8, 16);
  return Fixture{std::move(scene), std::move(camera), plan};
}

TEST(Determinism, TileRenderedTwiceGivesIdenticalBytes) {
  const Fixture f = make_fixture(16, 8, 32);
  const TileRenderer r(f.scene, f.camera, f.plan);
  PathCounters c1, c2;
  EXPECT_EQ(r.render_tile(1, &c1).serialize(), r.render_tile(1, &c2).serialize());
  EXPECT_EQ(c1.collisions, c2.collisions);
}

TEST(Determinism, UnitsInShuffledOrderMergeToTheSameBitsAsOneCall) {
  // 64 samples per pixel = 4 passes of 16, x 4 batches: rendered as one call,
  // and as 16 separate units in a shuffled order, each into its own film,
  // merged in the plan's (pass, batch) order.
  const Fixture f = make_fixture(16, 8, 64);
  ASSERT_EQ(f.plan.passes, 4);
  const TileRenderer r(f.scene, f.camera, f.plan);
  PathCounters counters;
  const FilmTile whole = r.render_tile(0, &counters);

  std::vector<WorkUnit> units;
  for (int p = 0; p < f.plan.passes; ++p)
    for (int b = 0; b < f.plan.batches; ++b) units.push_back({0, b, p});
  std::vector<WorkUnit> shuffled = units;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(5));
  ASSERT_NE(shuffled[0].pass * 4 + shuffled[0].batch, 0);  // really out of order
  std::vector<FilmTile> results;
  for (std::size_t i = 0; i < units.size(); ++i) results.push_back(r.empty_tile(0));
  for (const auto& u : shuffled) {
    const std::size_t slot = static_cast<std::size_t>(u.pass * f.plan.batches + u.batch);
    r.render_unit(u, &results[slot], &counters);
  }
  FilmTile merged = r.empty_tile(0);
  for (const auto& unit_film : results) merged.merge(unit_film);
  EXPECT_EQ(merged.serialize(), whole.serialize());
}

TEST(Determinism, ImageDoesNotDependOnThreadCount) {
  const Fixture f = make_fixture(24, 12, 8);
  const TileRenderer r(f.scene, f.camera, f.plan);
  Image one(24, 12), three(24, 12);
  render_image(r, &one, 1);
  render_image(r, &three, 3);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 24; ++x) ASSERT_EQ(one.rgb(x, y), three.rgb(x, y)) << x << "," << y;
}

// A frame of one tile renders several passes at once on several threads
// (local_render.cpp); its bytes, its stopping pass and its counters are those
// of one pass at a time, by target error and by samples alike, and every pass
// is reported in order.
TEST(Determinism, ProgressiveOneTileFrameDoesNotDependOnThreadCount) {
  const Fixture f = make_fixture(8, 8, 160);  // tile size 8: one tile, 10 passes of 16
  ASSERT_EQ(f.plan.tile_count(), 1);
  const TileRenderer r(f.scene, f.camera, f.plan);
  for (const std::optional<double> target : {std::optional<double>(), std::optional<double>(0.08)}) {
    std::vector<Image> images;
    std::vector<ProgressiveResult> results;
    for (const int threads : {1, 3, 4}) {
      StopCriteria stop;
      stop.target_relative_error = target;
      std::vector<int> reported;
      stop.after_pass = [&](int pass, const std::vector<FilmTile>&, double) { reported.push_back(pass); };
      images.emplace_back(8, 8);
      results.push_back(render_image_progressive(r, &images.back(), threads, stop));
      for (std::size_t i = 0; i < reported.size(); ++i) EXPECT_EQ(reported[i], static_cast<int>(i) + 1);
      EXPECT_EQ(static_cast<int>(reported.size()), results.back().passes);
    }
    if (target) {  // the test needs a stop before the last pass
      EXPECT_EQ(results[0].stopped_by, "target_error");
      EXPECT_LT(results[0].passes, f.plan.passes);
    }
    for (std::size_t k = 1; k < results.size(); ++k) {
      EXPECT_EQ(results[k].passes, results[0].passes);
      EXPECT_EQ(results[k].stopped_by, results[0].stopped_by);
      EXPECT_EQ(results[k].counters.paths, results[0].counters.paths);
      EXPECT_EQ(results[k].counters.collisions, results[0].counters.collisions);
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) ASSERT_EQ(images[k].rgb(x, y), images[0].rgb(x, y)) << x << "," << y;
    }
  }
}

TEST(Determinism, SeedChangesTheImage) {
  Fixture f = make_fixture(16, 8, 4);
  const TileRenderer a(f.scene, f.camera, f.plan);
  f.plan.seed = 100;
  const TileRenderer b(f.scene, f.camera, f.plan);
  PathCounters c;
  EXPECT_NE(a.render_tile(0, &c).serialize(), b.render_tile(0, &c).serialize());
}

}  // namespace
}  // namespace skyfarm
