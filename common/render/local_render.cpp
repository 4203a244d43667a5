#include "common/render/local_render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <vector>

#include "common/film/error_estimate.h"
#include "common/film/ground_pool.h"
#include "common/film/mirror_image.h"
#include "common/render/parallel.h"
#include "common/render/render_progress.h"

namespace skyfarm {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The plan's pooled ground pixels over the frame's tiles, in tile order.
GroundPool ground_pool(const RenderPlan& plan, const std::vector<FilmTile>& film) {
  GroundPool pool(plan.pooled_ground_row, plan.batches);
  if (pool.active())
    for (const auto& tile : film) pool.add(tile);
  return pool;
}
}  // namespace

LocalRenderResult render_image(const TileRenderer& renderer, Image* image, int threads,
                               const RenderProgress& progress) {
  const RenderPlan& plan = renderer.plan();
  // An adaptive plan's tiles wait for the whole frame's pilot; pooled ground
  // pixels need every tile's sums before any is resolved.
  if (plan.adaptive || plan.pooled_ground_row >= 0)
    return render_image_progressive(renderer, image, threads, StopCriteria{}, progress);
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
    s.error = error_sums(film, renderer.sun_pixels(), plan.width);
    image->resolve(film);  // disjoint pixels per tile
    if (progress) {
      const std::lock_guard<std::mutex> lock(mutex);
      progress(static_cast<double>(++done) / tiles);
    }
  });
  if (plan.mirrored) mirror_left_half(image);
  LocalRenderResult r;
  ErrorSums error;
  for (const auto& s : stats) {  // tile order: deterministic
    r.counters.add(s.counters);
    error.add(s.error);
  }
  r.pixels_without_estimate = error.unknown;
  r.estimate = error.relative_rms();
  r.estimated_relative_rms = r.estimate.value_or(0.0);
  r.error = error;
  return r;
}

ProgressiveResult render_image_progressive(const TileRenderer& renderer, Image* image, int threads,
                                           const StopCriteria& stop, const RenderProgress& progress) {
  const RenderPlan& plan = renderer.plan();
  const int tiles = plan.tile_count();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<FilmTile> film;
  for (int t = 0; t < tiles; ++t) film.push_back(renderer.empty_tile(t));
  std::vector<PathCounters> counters(static_cast<std::size_t>(tiles));
  ProgressiveResult r;
  r.stopped_by = "samples";
  std::int64_t done = 0;  // units (tile passes): 131072 x 65536 for the largest open-ended frame
  std::mutex mutex;
  GroundPool pool(plan.pooled_ground_row, plan.batches);  // of the film after each pass
  // Frames of fewer tiles than threads render several passes at once (a
  // frame of one tile would use one core); each tile's passes are merged in
  // pass order and each pass is evaluated in turn (error, stop criteria), so
  // the bytes and the stopping pass are those of one pass at a time; passes
  // rendered beyond the stop are dropped.  The adaptive pilot (pass 0) goes
  // alone: the passes after it need its allocation.
  const int workers = resolve_thread_count(threads);
  const int group = std::max(1, (workers + tiles - 1) / tiles);
  std::vector<std::vector<PathCounters>> unit_counters(
      static_cast<std::size_t>(group), std::vector<PathCounters>(static_cast<std::size_t>(tiles)));
  std::vector<FilmTile> passes_film;  // [pass in group * tiles + tile]
  double group_start = 0.0;
  for (int p = 0, group_begin = 0, group_end = 0; p < plan.passes; ++p) {
    if (p == group_end) {  // --- render passes [p, group_end) of every tile
      group_begin = p;
      group_end = std::min(plan.passes, p + ((p == 0 && plan.adaptive) ? 1 : group));
      const int k = group_end - p;
      group_start = seconds_since(t0);
      passes_film.clear();
      for (int j = 0; j < k; ++j)
        for (int t = 0; t < tiles; ++t) passes_film.push_back(renderer.empty_tile(t));
      parallel_for(static_cast<std::size_t>(k) * static_cast<std::size_t>(tiles), threads, [&](std::size_t u, int) {
        const int j = static_cast<int>(u) / tiles, t = static_cast<int>(u) % tiles, pass_index = p + j;
        const std::vector<PassSamples> samples = r.allocation && pass_index > 0
                                                     ? r.allocation->tile(t)
                                                     : std::vector<PassSamples>{};
        for (int b = 0; b < plan.batches; ++b)
          renderer.render_unit({t, b, pass_index, samples}, &passes_film[u],
                               &unit_counters[static_cast<std::size_t>(j)][static_cast<std::size_t>(t)]);
        if (progress) {
          const std::lock_guard<std::mutex> lock(mutex);
          const double samples_share =
              static_cast<double>(++done) / (static_cast<double>(tiles) * static_cast<double>(plan.passes));
          progress(render_progress(samples_share, seconds_since(t0), stop.time_limit_s, stop.target_relative_error,
                                   r.estimate));
        }
      });
    }
    // --- pass p: merged into the film in pass order, then evaluated
    const int j = p - group_begin;
    for (int t = 0; t < tiles; ++t) {
      film[static_cast<std::size_t>(t)].merge(passes_film[static_cast<std::size_t>(j * tiles + t)]);
      counters[static_cast<std::size_t>(t)].add(unit_counters[static_cast<std::size_t>(j)][static_cast<std::size_t>(t)]);
      unit_counters[static_cast<std::size_t>(j)][static_cast<std::size_t>(t)] = PathCounters{};
    }
    r.passes = p + 1;
    if (p == 0 && plan.adaptive) r.allocation = SampleAllocation::from_pilot(plan, film, renderer.sun_pixels());
    r.samples_per_pixel = r.allocation ? r.allocation->mean_samples_per_pixel(plan, r.passes)
                                       : plan.samples_after(r.passes);
    pool = ground_pool(plan, film);
    ErrorSums error;
    std::optional<FilmTile> scratch;
    for (const auto& tile : film)  // tile order
      error.add(error_sums(pool.shown(tile, &scratch), renderer.sun_pixels(), plan.width));
    r.estimate = error.relative_rms();
    r.estimated_relative_rms = r.estimate.value_or(0.0);
    r.pixels_without_estimate = error.unknown;
    r.error = error;
    // The passes of a group share its time, in equal parts.
    const double elapsed =
        group_start + (seconds_since(t0) - group_start) * (j + 1) / static_cast<double>(group_end - group_begin);
    r.history.emplace_back(elapsed, r.estimated_relative_rms);
    if (stop.after_pass) {  // the film as the image shows it
      if (pool.active()) {
        std::vector<FilmTile> shown;
        for (const auto& tile : film) shown.push_back(pool.shown(tile, &scratch));
        stop.after_pass(p + 1, shown, elapsed);
      } else {
        stop.after_pass(p + 1, film, elapsed);
      }
    }
    if (p + 1 == plan.passes) break;
    if (stop.target_relative_error && r.estimate && *r.estimate <= *stop.target_relative_error) {
      r.stopped_by = "target_error";
      break;
    }
    if (stop.time_limit_s && elapsed >= *stop.time_limit_s) {
      r.stopped_by = "time_limit";
      break;
    }
  }
  std::optional<FilmTile> scratch;
  for (const auto& tile : film) image->resolve(pool.shown(tile, &scratch));  // the last pass's pool
  if (plan.mirrored) mirror_left_half(image);
  for (const auto& c : counters) r.counters.add(c);
  return r;
}

}  // namespace skyfarm
