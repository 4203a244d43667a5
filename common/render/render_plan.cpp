#include "common/render/render_plan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/sampling/sampler.h"
#include "common/spectrum/wavelength_sampling.h"

namespace skyfarm {

void RenderPlan::tile_rect(int tile, int* x0, int* y0, int* w, int* h) const {
  const int tx = tile % tiles_x, ty = tile / tiles_x;
  *x0 = tx * tile_size;
  *y0 = ty * tile_size;
  *w = std::min(tile_size, rendered_width() - *x0);
  *h = std::min(tile_size, height - *y0);
}

int RenderPlan::pass_end_sample(int pass) const {
  return std::min(samples_per_pixel, (pass + 1) * samples_per_pass);
}

double RenderPlan::batch_min_nm(int batch) const { return batch_edge_nm(lambda_min_nm, lambda_max_nm, batch, batches); }
double RenderPlan::batch_max_nm(int batch) const {
  return batch_edge_nm(lambda_min_nm, lambda_max_nm, batch + 1, batches);
}

std::uint64_t RenderPlan::batch_seed(int batch) const {
  return fmix64(seed ^ (0x632be59bd9b4e019ULL * static_cast<std::uint64_t>(batch + 1)));
}

std::vector<WorkUnit> RenderPlan::units() const {
  std::vector<WorkUnit> out;
  out.reserve(static_cast<std::size_t>(unit_count()));
  for (int t = 0; t < tile_count(); ++t)
    for (int p = 0; p < passes; ++p)
      for (int b = 0; b < batches; ++b) out.push_back({t, b, p});
  return out;
}

RenderPlan make_render_plan(int width, int height, double lambda_min_nm, double lambda_max_nm, int batches,
                            int samples_per_pixel, std::uint64_t seed, int tile_size, int samples_per_pass,
                            bool mirrored) {
  if (width < 1 || height < 1 || batches < 1 || samples_per_pixel < 1 || tile_size < 1 || samples_per_pass < 1 ||
      !(lambda_max_nm > lambda_min_nm))
    throw std::invalid_argument("render plan: invalid dimensions, batches, samples or wavelength range");
  RenderPlan p;
  p.width = width;
  p.height = height;
  p.tile_size = tile_size;
  p.mirrored = mirrored && width % (2 * tile_size) == 0;
  p.tiles_x = (p.rendered_width() + tile_size - 1) / tile_size;
  p.tiles_y = (height + tile_size - 1) / tile_size;
  p.batches = batches;
  p.lambda_min_nm = lambda_min_nm;
  p.lambda_max_nm = lambda_max_nm;
  p.samples_per_pixel = samples_per_pixel;
  p.samples_per_pass = std::min(samples_per_pass, samples_per_pixel);
  p.passes = (samples_per_pixel + p.samples_per_pass - 1) / p.samples_per_pass;
  p.seed = seed;
  return p;
}

}  // namespace skyfarm

namespace skyfarm {

bool mirror_symmetric(const CameraSpec& camera, double sun_azimuth_deg, int tile_size) {
  if (camera.projection != Projection::kEquirectangular) return false;
  if (camera.pitch_deg != 0.0 || camera.roll_deg != 0.0) return false;
  if (camera.width % (2 * tile_size) != 0) return false;
  // yaw - sun azimuth a multiple of 180 degrees (to 1e-9 deg).
  const double d = std::fmod(std::abs(camera.yaw_deg - sun_azimuth_deg), 180.0);
  return d < 1e-9 || 180.0 - d < 1e-9;
}

}  // namespace skyfarm
