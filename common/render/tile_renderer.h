// Renders units of work (render_plan.h) into film tiles: for each pixel of
// the tile and each sample of the pass, a jittered camera ray (box filter),
// hero wavelengths importance-sampled inside the unit's batch, one path, and
// its XYZ and band radiance added to the film.  Samples whose film point has
// no direction (outside a fisheye's circle) are not counted, so an edge
// pixel is the mean over its part inside the circle.
//
// With plan.lut the pixels come from the LUT renderer (common/lut/lut_sky.h)
// instead: the sky at the pixel's centre, and for the pixels that see the
// sun disk the mean over 8 x 8 sub-pixel directions, so the disk's energy
// lands where the path tracer puts it; one sample per pixel and batch,
// deterministic.  The tables are built once per renderer (or shared).  A
// scene with clouds adds them to each LUT sample (common/lut/cloud_march.h,
// approximate); a clear scene builds nothing for clouds and takes exactly the
// code it took before clouds existed.
#pragma once
#include <memory>

#include "common/camera/camera.h"
#include "common/lut/cloud_march.h"
#include "common/film/film_tile.h"
#include "common/render/render_plan.h"
#include "common/render/volume_path_integrator.h"

namespace skyfarm {


class TileRenderer {
 public:
  TileRenderer(const Scene& scene, const Camera& camera, const RenderPlan& plan, IntegratorOptions options = {});
  // A LUT renderer on tables built elsewhere (a cache); `lut` must match the scene.
  // `clouds`: the cloud march's options where the scene has clouds.
  TileRenderer(const Scene& scene, const Camera& camera, const RenderPlan& plan,
               std::shared_ptr<const LutSky> lut, const CloudMarchOptions& clouds = {});

  // A fresh film tile for tile t (all batches, zero).
  FilmTile empty_tile(int tile) const;
  // Adds the samples of one unit to `film` (which must be tile unit.tile).
  void render_unit(const WorkUnit& unit, FilmTile* film, PathCounters* counters) const;
  // All passes and batches of a tile, merged in canonical order.  Uniform
  // plans only (std::logic_error otherwise): an adaptive plan's later passes
  // need every tile's pilot first.
  FilmTile render_tile(int tile, PathCounters* counters) const;

  const RenderPlan& plan() const { return plan_; }
  // Pixels that see the sun disk, left out of the image-level error estimate.
  const std::vector<std::uint32_t>& sun_pixels() const { return sun_pixels_; }
  // The LUT renderer's cloud march, null unless plan.lut and the scene has clouds.
  const CloudMarch* lut_clouds() const { return cloud_march_.get(); }

 private:
  void render_unit_lut(const WorkUnit& unit, FilmTile* film) const;
  void build_lut_clouds(const CloudMarchOptions& options);

  const Scene& scene_;
  const Camera& camera_;
  RenderPlan plan_;
  VolumePathIntegrator integrator_;
  std::vector<std::uint32_t> sun_pixels_;
  std::shared_ptr<const LutSky> lut_;  // plan.lut only
  std::shared_ptr<const CloudMarch> cloud_march_;  // plan.lut and clouds only
};

}  // namespace skyfarm
