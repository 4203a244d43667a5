#include "common/render/render_plan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/core/constants.h"
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

int RenderPlan::blocks_x(int tile) const {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  tile_rect(tile, &x0, &y0, &w, &h);
  return (w + kAllocationBlock - 1) / kAllocationBlock;
}

int RenderPlan::block_count(int tile) const {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  tile_rect(tile, &x0, &y0, &w, &h);
  return blocks_x(tile) * ((h + kAllocationBlock - 1) / kAllocationBlock);
}

int RenderPlan::block_of(int tile, int x, int y) const {
  const int tx = tile % tiles_x, ty = tile / tiles_x;
  return ((y - ty * tile_size) / kAllocationBlock) * blocks_x(tile) + (x - tx * tile_size) / kAllocationBlock;
}

void RenderPlan::sample_range(const WorkUnit& u, int x, int y, int* first, int* end) const {
  if (ground_pooled(y)) {  // passes <= samples_per_pixel, so sample u.pass exists
    *first = u.pass;
    *end = u.pass + 1;
    return;
  }
  *first = pass_first_sample(u.pass);
  *end = pass_end_sample(u.pass);
  const int n = u.pass > 0 && !u.samples.empty() ? u.samples[static_cast<std::size_t>(block_of(u.tile, x, y))].of(x, y) : 0;
  if (n <= 0) return;
  *first = samples_per_pass + (u.pass - 1) * n;
  *end = *first + allocated_samples(u.pass, n);
}

// A short last pass keeps its share of n.
int RenderPlan::allocated_samples(int pass, int n) const {
  const int length = pass_end_sample(pass) - pass_first_sample(pass);
  if (length == samples_per_pass) return n;
  return std::max(1, static_cast<int>(std::lround(static_cast<double>(n) * length / samples_per_pass)));
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

int first_ground_row(const CameraSpec& camera) {
  if (camera.projection != Projection::kEquirectangular) return -1;
  if (camera.pitch_deg != 0.0 || camera.roll_deg != 0.0) return -1;
  // Camera::film_to_direction: the zenith component is cos(pi fy / height).
  for (int y = camera.height / 2; y < camera.height; ++y)
    if (std::cos(kPi * static_cast<double>(y) / camera.height) < 0.0) return y;
  return -1;
}

bool mirror_symmetric(const CameraSpec& camera, double sun_azimuth_deg, int tile_size) {
  if (camera.projection != Projection::kEquirectangular) return false;
  if (camera.pitch_deg != 0.0 || camera.roll_deg != 0.0) return false;
  if (camera.width % (2 * tile_size) != 0) return false;
  // yaw - sun azimuth a multiple of 180 degrees (to 1e-9 deg).
  const double d = std::fmod(std::abs(camera.yaw_deg - sun_azimuth_deg), 180.0);
  return d < 1e-9 || 180.0 - d < 1e-9;
}

}  // namespace skyfarm
