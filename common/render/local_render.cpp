#include "common/render/local_render.h"

#include <cmath>
#include <mutex>
#include <vector>

#include "common/render/parallel.h"

namespace skyfarm {

LocalRenderResult render_image(const TileRenderer& renderer, Image* image, int threads,
                               const RenderProgress& progress) {
  const RenderPlan& plan = renderer.plan();
  const int tiles = plan.tile_count();
  struct TileStats {
    PathCounters counters;
    double sum_var = 0.0, sum_Y2 = 0.0;
    int unknown = 0;
  };
  std::vector<TileStats> stats(static_cast<std::size_t>(tiles));
  std::mutex mutex;
  int done = 0;
  parallel_for(static_cast<std::size_t>(tiles), threads, [&](std::size_t t, int) {
    TileStats& s = stats[t];
    const FilmTile film = renderer.render_tile(static_cast<int>(t), &s.counters);
    for (int y = film.y0(); y < film.y0() + film.height(); ++y)
      for (int x = film.x0(); x < film.x0() + film.width(); ++x) {
        const auto mean = film.mean_xyz(x, y);
        const auto var = film.luminance_variance_of_mean(x, y);
        if (!mean) continue;  // pixel never traced (outside a fisheye circle)
        if (!var) {
          ++s.unknown;
          continue;
        }
        s.sum_var += *var;
        s.sum_Y2 += mean->y * mean->y;
      }
    image->resolve(film);  // disjoint pixels per tile
    if (progress) {
      const std::lock_guard<std::mutex> lock(mutex);
      progress(++done, tiles);
    }
  });
  LocalRenderResult r;
  double sum_var = 0.0, sum_Y2 = 0.0;
  for (const auto& s : stats) {  // tile order: deterministic
    r.counters.add(s.counters);
    sum_var += s.sum_var;
    sum_Y2 += s.sum_Y2;
    r.pixels_without_estimate += s.unknown;
  }
  r.estimated_relative_rms = sum_Y2 > 0.0 ? std::sqrt(sum_var / sum_Y2) : 0.0;
  return r;
}

}  // namespace skyfarm
