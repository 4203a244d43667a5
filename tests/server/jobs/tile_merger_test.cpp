// The tile merger keeps only a few tiles in memory yet merges every unit in
// canonical order: with a budget of one tile, results delivered in a shuffled
// order give the same image as a local render.
#include "server/jobs/tile_merger.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <unistd.h>

#include "api/render_spec.h"
#include "common/render/local_render.h"

namespace skyfarm::server {
namespace {

TEST(TileMerger, TinyMemoryBudgetStillMergesIdentically) {
  const auto request = api::parse_render_request(R"({"sun": {"zenith_deg": 35, "azimuth_deg": 10},
    "camera": {"projection": "equirectangular", "width": 96, "height": 64}, "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 32}})");
  const RenderSetup setup = make_render_setup(api::render_spec(request));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  const auto dir = std::filesystem::temp_directory_path() / ("skyfarm_merger_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  TileMerger merger(setup.plan, dir, 1);  // at most one tile in memory
  std::vector<WorkUnit> units = setup.plan.units();
  std::shuffle(units.begin(), units.end(), std::mt19937(3));
  PathCounters counters;
  for (const auto& u : units) {
    FilmTile film = renderer.empty_tile(u.tile);
    renderer.render_unit(u, &film, &counters);
    EXPECT_TRUE(merger.add(u, std::move(film)));
  }
  EXPECT_TRUE(merger.complete());
  Image farm(96, 64), local(96, 64);
  merger.resolve(&farm);
  render_image(renderer, &local, 1);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 96; ++x) ASSERT_EQ(farm.rgb(x, y), local.rgb(x, y)) << x << "," << y;
  // A second merger on the same folder resumes with everything merged.
  const TileMerger reloaded(setup.plan, dir, 1);
  EXPECT_TRUE(reloaded.complete());
  EXPECT_TRUE(reloaded.merged(WorkUnit{0, 0, 0}));
}

// The pass gate of early-stopping jobs: with a limit of k passes, results of
// pass k wait even when all of them have arrived, so a target-error check
// sees every pass one at a time (it once let two passes through at once, and
// a farm job stopped a pass later than the same local render).
TEST(TileMerger, PassLimitMergesExactlyThatManyPasses) {
  const auto request = api::parse_render_request(R"({"sun": {"zenith_deg": 35, "azimuth_deg": 10},
    "camera": {"projection": "equirectangular", "width": 32, "height": 16}, "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 64}})");
  const RenderSetup setup = make_render_setup(api::render_spec(request));
  ASSERT_GE(setup.plan.passes, 4);
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  const auto dir = std::filesystem::temp_directory_path() / ("skyfarm_gate_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  TileMerger merger(setup.plan, dir);
  merger.set_pass_limit(1);
  PathCounters counters;
  for (const auto& u : setup.plan.units()) {
    if (u.pass >= 3) continue;
    FilmTile film = renderer.empty_tile(u.tile);
    renderer.render_unit(u, &film, &counters);
    merger.add(u, std::move(film));
  }
  EXPECT_EQ(merger.complete_passes(), 1);
  merger.set_pass_limit(2);
  EXPECT_EQ(merger.complete_passes(), 2);
  merger.set_pass_limit(3);
  EXPECT_EQ(merger.complete_passes(), 3);
  std::filesystem::remove_all(dir);
}

// With a persistence interval, merges after a tile's last write are not on
// disk; a crash (the merger never destroyed) then loses exactly those, a
// restarted merger resumes from what the files record, and the units merged
// again give the same sums as an uninterrupted merge.
TEST(TileMerger, MergesNotYetWrittenAreMergedAgainAfterACrash) {
  const RenderPlan plan = make_render_plan(64, 32, 360.0, 830.0, 2, 48, 1);  // 2 tiles x 2 batches x 3 passes
  ASSERT_EQ(plan.unit_count(), 12);
  auto result = [&](const WorkUnit& u) {
    int x0 = 0, y0 = 0, w = 0, h = 0;
    plan.tile_rect(u.tile, &x0, &y0, &w, &h);
    FilmTile film(x0, y0, w, h, plan.batches);
    const double v = 1.0 + u.pass * 0.25 + u.batch * 0.125;  // distinct per unit: order matters
    film.set_sums(x0, y0, u.batch, PixelBatchSums{16.0, v, v, v, v * v, v, v, v, v});
    return film;
  };
  const auto dir = std::filesystem::temp_directory_path() / ("skyfarm_merger_crash_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const std::vector<WorkUnit> units = plan.units();
  // The merger that "crashes": each tile's first merge is written, the rest wait for the hour.
  auto* crashed = new TileMerger(plan, dir / "a", 64u << 20, true, std::chrono::hours(1));
  for (const auto& u : units) ASSERT_TRUE(crashed->add(u, result(u)));
  EXPECT_TRUE(crashed->complete());
  EXPECT_EQ(crashed->dirty_tiles(), 2u);
  // Never destroyed (a destructor would flush): the crash.  Deliberately leaked.
  TileMerger restarted(plan, dir / "a");
  EXPECT_EQ(restarted.merged_units(), 2) << "the first unit of each tile, as written";
  int again = 0;
  for (const auto& u : units)
    if (!restarted.merged(u)) again += restarted.add(u, result(u)) ? 1 : 0;
  EXPECT_EQ(again, 10);
  EXPECT_TRUE(restarted.complete());

  TileMerger direct(plan, dir / "b");
  for (const auto& u : units) ASSERT_TRUE(direct.add(u, result(u)));
  for (int t = 0; t < plan.tile_count(); ++t)
    EXPECT_EQ(restarted.sums_of(t).serialize(), direct.sums_of(t).serialize()) << "tile " << t;

  // flush() writes everything: a reload sees every unit.
  crashed->flush();
  EXPECT_EQ(crashed->dirty_tiles(), 0u);
  EXPECT_TRUE(TileMerger(plan, dir / "a").complete());
  std::filesystem::remove_all(dir);
}

// A reclaimed job's tiles stay gone: merges not yet written when its files
// are removed are dropped, not written by a later flush or the destructor.
TEST(TileMerger, RemovedFilesAreNotWrittenAgainByPendingMerges) {
  const RenderPlan plan = make_render_plan(64, 32, 360.0, 830.0, 2, 48, 1);  // 2 tiles x 2 batches x 3 passes
  const auto dir = std::filesystem::temp_directory_path() / ("skyfarm_merger_removed_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  {
    TileMerger merger(plan, dir, 64u << 20, true, std::chrono::hours(1));
    for (const auto& u : plan.units()) {
      int x0 = 0, y0 = 0, w = 0, h = 0;
      plan.tile_rect(u.tile, &x0, &y0, &w, &h);
      FilmTile film(x0, y0, w, h, plan.batches);
      film.set_sums(x0, y0, u.batch, PixelBatchSums{16.0, 1, 1, 1, 1, 1, 1, 1, 1});
      ASSERT_TRUE(merger.add(u, std::move(film)));
    }
    ASSERT_GT(merger.dirty_tiles(), 0u);
    merger.remove_files();
    EXPECT_EQ(merger.dirty_tiles(), 0u);
    merger.flush();
    EXPECT_EQ(merger.bytes_on_disk(), 0);
  }
  int tiles = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) tiles += e.path().extension() == ".bin";
  EXPECT_EQ(tiles, 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace skyfarm::server

namespace skyfarm::server {
namespace {

// A result of the right origin but another size is refused at once (it
// could never merge: the unit would wait for ever); the tile files are
// counted on disk and removed whole by remove_files, the counts kept.
TEST(TileMerger, AResultOfAnotherSizeIsRefusedAndFilesAreCountedAndRemoved) {
  const auto request = api::parse_render_request(R"({"sun": {"zenith_deg": 35, "azimuth_deg": 10},
    "camera": {"projection": "equirectangular", "width": 48, "height": 16}, "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 16}})");
  const RenderSetup setup = make_render_setup(api::render_spec(request));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  const auto dir = std::filesystem::temp_directory_path() / ("skyfarm_merger_size_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  TileMerger merger(setup.plan, dir);
  const WorkUnit u{0, 0, 0};
  EXPECT_THROW(merger.add(u, FilmTile(0, 0, 31, 16, 2)), FilmTileDecodeError);
  EXPECT_THROW(merger.add(u, FilmTile(0, 0, 32, 15, 2)), FilmTileDecodeError);
  EXPECT_THROW(merger.add(u, FilmTile(0, 0, 32, 16, 3)), FilmTileDecodeError);
  EXPECT_FALSE(merger.received(u)) << "nothing waits";
  EXPECT_EQ(merger.bytes_on_disk(), 0);
  PathCounters counters;
  for (const auto& unit : setup.plan.units()) {
    FilmTile film = renderer.empty_tile(unit.tile);
    renderer.render_unit(unit, &film, &counters);
    ASSERT_TRUE(merger.add(unit, std::move(film)));
  }
  ASSERT_TRUE(merger.complete());
  std::int64_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += static_cast<std::int64_t>(e.file_size());
  EXPECT_EQ(merger.bytes_on_disk(), files);
  EXPECT_EQ(TileMerger(setup.plan, dir).bytes_on_disk(), files) << "counted again when reloaded";
  merger.remove_files();
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  EXPECT_EQ(merger.bytes_on_disk(), 0);
  EXPECT_TRUE(merger.complete()) << "the counts stay";
}

}  // namespace
}  // namespace skyfarm::server
