// The tile merger keeps only a few tiles in memory yet merges every unit in
// canonical order: with a budget of one tile, results delivered in a shuffled
// order give the same image as a local render.
#include "server/tile_merger.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <unistd.h>

#include "api/render_setup.h"
#include "common/render/local_render.h"

namespace skyfarm::server {
namespace {

TEST(TileMerger, TinyMemoryBudgetStillMergesIdentically) {
  const auto request = api::parse_render_request(R"({"sun": {"zenith_deg": 35, "azimuth_deg": 10},
    "camera": {"projection": "equirectangular", "width": 96, "height": 64}, "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 32}})");
  const api::RenderSetup setup = api::make_render_setup(request);
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
  const api::RenderSetup setup = api::make_render_setup(request);
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
  const api::RenderSetup setup = api::make_render_setup(request);
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
