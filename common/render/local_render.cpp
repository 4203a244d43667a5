#include "common/render/local_render.h"

#include <cmath>
#include <mutex>
#include <vector>

#include "common/film/error_estimate.h"
#include "common/render/parallel.h"

namespace skyfarm {

LocalRenderResult render_image(const TileRenderer& renderer, Image* image, int threads,
                               const RenderProgress& progress) {
  const RenderPlan& plan = renderer.plan();
  const int tiles = plan.tile_count();
  struct TileStats {
    PathCounters counters;
    ErrorSums error;
  };
  std::vector<TileStats> stats(static_cast<std::size_t>(tiles));
  std::mutex mutex;
  int done = 0;
  parallel_for(static_cast<std::size_t>(tiles), threads, [&](std::size_t t, int) {
    TileStats& s = stats[t];
    const FilmTile film = renderer.render_tile(static_cast<int>(t), &s.counters);
    s.error = error_sums(film);
    image->resolve(film);  // disjoint pixels per tile
    if (progress) {
      const std::lock_guard<std::mutex> lock(mutex);
      progress(++done, tiles);
    }
  });
  LocalRenderResult r;
  ErrorSums error;
  for (const auto& s : stats) {  // tile order: deterministic
    r.counters.add(s.counters);
    error.add(s.error);
  }
  r.pixels_without_estimate = error.unknown;
  r.estimate = error.relative_rms();
  r.estimated_relative_rms = r.estimate.value_or(0.0);
  return r;
}

}  // namespace skyfarm
