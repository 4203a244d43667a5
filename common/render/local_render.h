// Renders a whole image on this machine: the plan's tiles on `threads`
// threads, each tile's units merged in canonical order (tile_renderer.h), then
// resolved into the output image.  The result does not depend on the thread
// count.  Also reports the image-level estimated relative RMS error of
// luminance, sqrt(sum_i var(Y_i) / sum_i Y_i^2) over the pixels with an
// estimate (ErrorSums::relative_rms).
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/film/error_estimate.h"
#include "common/film/image.h"
#include "common/render/sample_allocation.h"
#include "common/render/tile_renderer.h"

namespace skyfarm {

// Called after each finished tile with the render's progress in [0, 1]
// (render_progress.h: towards the first of its limits); from worker threads, serialised.
using RenderProgress = std::function<void(double progress)>;

struct LocalRenderResult {
  PathCounters counters;
  double estimated_relative_rms = 0.0;  // NaN-free; 0 when nothing has an estimate
  std::optional<double> estimate;       // the same, nullopt when nothing has an estimate
  int pixels_without_estimate = 0;      // fewer than 2 samples in some batch
  ErrorSums error;                      // all of it, per channel too (error_estimate.h)
};

LocalRenderResult render_image(const TileRenderer& renderer, Image* image, int threads,
                               const RenderProgress& progress = {});

// When to stop before the plan's last sample: after
// the first whole pass at which the estimated relative RMS error is at most
// the target, or the first whole pass completed after the time limit.
struct StopCriteria {
  std::optional<double> target_relative_error;
  std::optional<double> time_limit_s;
  // Called after every whole pass with (passes done, the film's tiles as the
  // image shows them, i.e. with a pooled ground applied, elapsed s): for benchmarks.
  std::function<void(int, const std::vector<FilmTile>&, double)> after_pass;
};

struct ProgressiveResult : LocalRenderResult {
  int passes = 0;             // passes rendered (every tile)
  double samples_per_pixel = 0.0;               // the mean over the rendered pixels
  std::optional<SampleAllocation> allocation;   // adaptive plans, after the pilot
  std::string stopped_by;     // "samples", "target_error" or "time_limit"
  std::vector<std::pair<double, double>> history;  // (elapsed s, estimate) after each pass
};

// Renders pass by pass over the whole frame (all tiles of pass p before any
// of pass p + 1; an adaptive plan's allocation from pass 0, the pilot) and stops by `stop`; the same passes and stopping rule as the
// farm, so the same request gives the same bytes.  A frame of fewer tiles
// than threads renders several passes at once and evaluates them one by one
// (the same bytes and stopping pass; a 64x32 mirrored frame, one tile, used
// one core of two before).  Keeps the whole film in memory (width x height x
// batches x 48 bytes), unlike render_image().
ProgressiveResult render_image_progressive(const TileRenderer& renderer, Image* image, int threads,
                                           const StopCriteria& stop, const RenderProgress& progress = {});

}  // namespace skyfarm
