// Renders a whole image on this machine: the plan's tiles on `threads`
// threads, each tile's units merged in canonical order (tile_renderer.h), then
// resolved into the output image.  The result does not depend on the thread
// count.  Also reports the image-level estimated relative RMS error of
// luminance, sqrt(sum_i var(Y_i) / sum_i Y_i^2) over the pixels with an
// estimate (DESIGN §6).
#pragma once
#include <functional>
#include <optional>

#include "common/film/image.h"
#include "common/render/tile_renderer.h"

namespace skyfarm {

// Called after each finished tile with (tiles done, tiles total); from worker threads, serialised.
using RenderProgress = std::function<void(int done, int total)>;

struct LocalRenderResult {
  PathCounters counters;
  double estimated_relative_rms = 0.0;  // NaN-free; 0 when nothing has an estimate
  std::optional<double> estimate;       // the same, nullopt when nothing has an estimate
  int pixels_without_estimate = 0;      // fewer than 2 samples in some batch
};

LocalRenderResult render_image(const TileRenderer& renderer, Image* image, int threads,
                               const RenderProgress& progress = {});

}  // namespace skyfarm
