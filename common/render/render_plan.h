// How a render is cut into units of work: image tiles x
// wavelength batches x sample passes.  A pure function of the request, so a
// unit means the same samples wherever and whenever it is rendered.
//
//   tile_size          square tiles of this many pixels (edge tiles smaller)
//   samples_per_pass   samples per pixel in one pass (the last may be short)
//   batches            equal wavelength batches of [lambda_min, lambda_max]
//
// Unit (tile t, batch b, pass p) renders samples [p S, min((p+1) S, spp)) of
// every pixel of tile t at wavelengths in batch b, with random numbers keyed
// by (seed of batch b, pixel index y W + x, sample index, dimension).  Units
// of one tile are merged in pass order (then batch order), so the sums are
// bit-identical however the units were scheduled.
//
// Adaptive plans (sample_allocation.h): pass 0 is the uniform pilot; a unit
// of a later pass carries, for each kAllocationBlock-square block of its
// tile, the samples per pass n of the even and odd pixels (parity of x + y),
// and renders samples [S + (p - 1) n, S + p n) of each pixel (sample_range; a
// short last pass in proportion).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/camera/camera_spec.h"

namespace skyfarm {

// Samples per pixel per pass by the parity of x + y; 0 = the plan's uniform count.
struct PassSamples {
  int even = 0, odd = 0;
  int of(int x, int y) const { return ((x + y) & 1) != 0 ? odd : even; }
  bool uniform() const { return even == 0 && odd == 0; }
  bool operator==(const PassSamples&) const = default;
};

struct WorkUnit {
  int tile = 0, batch = 0, pass = 0;
  // Adaptive plans, passes >= 1 (sample_allocation.h): the samples per pass
  // of each allocation block of the tile (RenderPlan::block_of); empty = uniform.
  std::vector<PassSamples> samples{};
};

struct RenderPlan {
  int width = 0, height = 0;
  int tile_size = 32;
  int tiles_x = 0, tiles_y = 0;
  int batches = 1;
  double lambda_min_nm = 360.0, lambda_max_nm = 830.0;
  int samples_per_pixel = 1;
  int samples_per_pass = 16;
  int passes = 1;
  std::uint64_t seed = 1;
  // Mirror symmetry: when the view is symmetric about the sun's
  // vertical plane, only columns [0, width / 2) are rendered (tiles cover
  // them alone) and the right half is their mirror image (mirror_image.h).
  bool mirrored = false;
  // The LUT renderer (method "lut", common/lut/): one deterministic sample
  // per pixel and batch from the tables instead of paths; approximate.
  bool lut = false;
  // Russian roulette with the LUT sky as a control variate
  // (IntegratorOptions::roulette_control): path-traced renders with the sun
  // at most kRouletteControlMaxSunZenith_deg from the observer's zenith,
  // where it pays (1.1-1.4x; at 90 deg 0.96x, at twilight worse:
  // docs/experiments/2026-11-22-path-tracer-variance.md).
  bool roulette_control = false;
  static constexpr double kRouletteControlMaxSunZenith_deg = 85.0;
  // The shadow guide (IntegratorOptions::shadow_guide, shadow_guide.h):
  // path-traced renders with the sun below the observer's horizon, where
  // the light of the dark air comes from a small part of the sky.  By day no
  // vertex would use it (the sun is below few vertices' horizontal), and at
  // sunset (90 deg) it measured the same error for ~0.14 s of building.
  bool shadow_guide = false;
  // Variance-aware sample allocation after a uniform pilot pass
  // (sample_allocation.h): path-traced plans of two passes or more whose
  // request asks for it ("quality.adaptive").
  bool adaptive = false;
  static constexpr int kAllocationBlock = 8;
  // The ground under an observer at 0 m (film/ground_pool.h):
  // rows [pooled_ground_row, height) look only at the ground at the
  // observer's feet, all with the same radiance; each of their pixels traces
  // one sample per pass (sample index = the pass) and their sums are pooled
  // before the image is resolved.  Exact because the ground is one Lambertian
  // sphere and the atmosphere horizontally uniform (a scene with surfaces on
  // the ground would not qualify).  -1: none.
  int pooled_ground_row = -1;
  bool ground_pooled(int y) const { return pooled_ground_row >= 0 && y >= pooled_ground_row; }
  int rendered_width() const { return mirrored ? width / 2 : width; }

  int tile_count() const { return tiles_x * tiles_y; }
  // 64-bit: a 16384 x 8192 frame with no sample cap (a target error or time
  // limit alone) has 131072 tiles x 65536 passes.
  std::int64_t unit_count() const {
    return static_cast<std::int64_t>(tile_count()) * batches * static_cast<std::int64_t>(passes);
  }
  // Pixel rectangle of tile t.
  void tile_rect(int tile, int* x0, int* y0, int* w, int* h) const;
  // Samples [first, end) of pass p.
  int pass_first_sample(int pass) const { return pass * samples_per_pass; }
  int pass_end_sample(int pass) const;
  // Samples per pixel after `passes` whole passes of a uniform plan.
  int samples_after(int passes) const { return std::min(samples_per_pixel, passes * samples_per_pass); }
  // Allocation blocks of tile t (row-major, kAllocationBlock pixels square,
  // edge blocks smaller), and the block of pixel (x, y) of that tile.
  int blocks_x(int tile) const;
  int block_count(int tile) const;
  int block_of(int tile, int x, int y) const;
  // Samples [*first, *end) of pixel (x, y) in unit u (the pass's uniform
  // range, or u.samples' count for the pixel's parity after the pilot; the
  // one sample u.pass for a pooled ground pixel).
  void sample_range(const WorkUnit& u, int x, int y, int* first, int* end) const;
  // Samples in pass p >= 1 of a pixel allocated n per pass.
  int allocated_samples(int pass, int n) const;
  // Wavelength range of batch b (shared edges are bit-identical).
  double batch_min_nm(int batch) const;
  double batch_max_nm(int batch) const;
  // The seed of batch b's random numbers.
  std::uint64_t batch_seed(int batch) const;
  // Units in canonical order: tile-major, then pass, then batch.
  std::vector<WorkUnit> units() const;
};

// Whether the roulette control pays for a sun this far from the observer's
// zenith (RenderPlan::roulette_control; path probes follow the same rule).
inline bool roulette_control_pays(double sun_zenith_deg) {
  return sun_zenith_deg <= RenderPlan::kRouletteControlMaxSunZenith_deg;
}

// Whether the shadow guide pays for a sun this far from the observer's
// zenith (RenderPlan::shadow_guide; path probes follow the same rule).
inline bool shadow_guide_pays(double sun_zenith_deg) { return sun_zenith_deg > 90.0; }

RenderPlan make_render_plan(int width, int height, double lambda_min_nm, double lambda_max_nm, int batches,
                            int samples_per_pixel, std::uint64_t seed, int tile_size = 32, int samples_per_pass = 16,
                            bool mirrored = false);

// Whether an image may be rendered half and mirrored: an equirectangular view
// with no pitch or roll whose centre column looks along (or against) the
// sun's azimuth, so the sun's vertical plane is the middle of the image, and
// a width of whole tile pairs.  The atmosphere is horizontally uniform and the
// observer on the plane, so the sky is mirror-symmetric about it.
bool mirror_symmetric(const CameraSpec& camera, double sun_azimuth_deg, int tile_size = 32);

// The first row of an image whose every film point looks below the horizon
// (RenderPlan::pooled_ground_row), for an observer at 0 m: equirectangular
// views with no pitch or roll, where row y spans zenith angles pi [y, y + 1)
// / height, so the rows from the first y with cos(pi y / height) < 0 on; -1
// for other cameras or when no row qualifies.
int first_ground_row(const CameraSpec& camera);

}  // namespace skyfarm
