// Whether a worker's result for a unit is exactly the result that unit asks
// for, judged from the plan and the camera alone (never from the result):
//
//   geometry   the FilmTile is the unit's tile: x0, y0, width, height of
//              RenderPlan::tile_rect and the plan's batch count;
//   counts     every pixel of the unit's batch holds the samples the
//              renderer (common/render/tile_renderer.cpp) adds for that unit,
//              and every other batch is empty (a unit fills one batch);
//   sums       finite, and a pixel with no samples has all sums zero.
//
// The samples of pixel (x, y) in unit u, as TileRenderer::render_unit adds them:
//   - none for a pixel the camera does not trace (Camera::pixel_exists: a
//     fisheye's pixels whose centre lies outside the image circle);
//   - path plans: the samples [first, end) of RenderPlan::sample_range (the
//     pass's uniform range; after an adaptive pilot the unit's count for the
//     pixel's block and parity, a short last pass in proportion; one sample
//     for a pooled ground pixel), less those whose jittered film point has no
//     direction (a fisheye pixel the circle crosses: the jitter is the first
//     two numbers of the sample's Sampler, recomputed here);
//   - LUT plans: one sample when the pixel's centre has a direction (a pixel
//     that sees the sun disk: when any of its 8 x 8 sub-pixel points has).
// A sample with a non-finite value is not added but counted in the tile's
// rejected_samples (film_tile.h): a pixel may hold fewer than expected by
// exactly the tile's rejected count in all, never more.  Such a sample is
// deterministic, so refusing it would only fail the unit on every worker.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "common/camera/camera.h"
#include "common/film/film_tile.h"
#include "common/render/render_plan.h"

namespace skyfarm::server {

class UnitResultCheck {
 public:
  // sun_pixels: sorted pixel indices y W + x that see the sun disk (render/sun_pixels.h).
  UnitResultCheck(const RenderPlan& plan, const Camera& camera, std::vector<std::uint32_t> sun_pixels);

  // "" when `film` is exactly unit's result; otherwise what is wrong, naming
  // the first offending pixel.  `unit` carries its samples per block after
  // an adaptive pilot (WorkUnit::samples), as it was sent.
  std::string check(const WorkUnit& unit, const FilmTile& film) const;

  // The samples the renderer adds to pixel (x, y) (image coordinates, inside
  // the unit's tile) of the unit's batch.
  int expected_samples(const WorkUnit& unit, int x, int y) const;

 private:
  bool whole_pixel_has_directions(int x, int y) const;

  RenderPlan plan_;
  Camera camera_;
  std::vector<std::uint32_t> sun_pixels_;
};

}  // namespace skyfarm::server
