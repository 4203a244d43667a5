// Variance-aware sample allocation (more samples where the error is largest,
// without biasing the image): after a uniform pilot pass, every
// block of 8 x 8 pixels (RenderPlan::kAllocationBlock) gets its own number of
// samples per pass, more where the pilot's luminance noise is larger, for
// the same mean number of samples.
//
// Parameters (RenderPlan, request "quality.adaptive")
//   pilot        pass 0, samples_per_pass samples in every pixel, as without
//                allocation
//   kMinRatio,   a block's samples per pass stay within [S / kMinRatio,
//   kMaxRatio    S kMaxRatio] of the uniform S = samples_per_pass: 8 to 64
//                for S = 16.  Bounded below because the pilot is a noisy
//                guide where rare bright paths carry the variance (twilight:
//                a block whose pilot saw none of them would get few samples
//                and keep the next one's whole weight); at twilight over 7
//                seeds the floor of S / 2 gave an RMS error of 0.279 where
//                S / 4 gave 0.292 and uniform samples 0.296, and noon, 85
//                and 90 degrees the same error with either floor
//
// Why it pays: the image error sqrt(sum_i var_i / sum_i Y_i^2) (error_estimate.h)
// sums the pixels' absolute variances s_i^2 / n_i.  With n_i samples of
// per-sample standard deviation s_i and sum_i n_i fixed, sum_i s_i^2 / n_i is
// least for n_i proportional to s_i (Lagrange); a group of pixels that shares
// one n gets n proportional to its RMS s.  The gain over uniform n is
// mean(s^2) / mean(s)^2 (measured:
// docs/experiments/2026-11-22-sample-allocation.md).
//
// Why it does not bias the image: a pixel's mean over n samples is unbiased
// when n does not depend on those samples.  Pixels are split like a
// checkerboard by the parity of x + y (image coordinates), and the pixels of
// one parity get their n from the pilot of the OTHER parity only: the block's
// RMS s of those pixels, and a normalising factor (a fixed total per parity)
// computed from that parity's pilot alone.  The pilot's own counts are fixed
// (samples_per_pass everywhere), and the paths of different pixels are
// independent (sampler.h), so a pixel's n is independent of all its samples.
// (Stopping at a target error still depends on the whole image's estimate,
// as it does without allocation.)
//
// Pixels that see the sun disk are left out of the pilot's statistics, as
// they are of the image's error estimate (sun_pixels.h).  A parity group with
// no pilot data on its other side keeps S.  Deterministic: the same pilot
// sums give the same allocation, in any process.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "common/film/film_tile.h"
#include "common/render/render_plan.h"

namespace skyfarm {

class SampleAllocation {
 public:
  static constexpr double kMinRatio = 2.0, kMaxRatio = 4.0;
  // Per block of a tile: the RMS standard error of the pilot's luminance
  // means of its even and odd pixels (NaN: none with an estimate).
  using BlockStatistics = std::vector<std::array<double, 2>>;

  // From the merged pilot (pass 0 only) of every tile, in tile order;
  // `excluded`: sorted sun-disk pixel indices y * width + x.
  static SampleAllocation from_pilot(const RenderPlan& plan, const std::vector<FilmTile>& pilot,
                                     const std::vector<std::uint32_t>& excluded);
  // The same in two steps, for a caller that holds one tile at a time (the
  // farm's merger): each tile's statistics, then the allocation.
  static BlockStatistics pilot_statistics(const RenderPlan& plan, int tile, const FilmTile& pilot,
                                          const std::vector<std::uint32_t>& excluded);
  static SampleAllocation from_statistics(const RenderPlan& plan, const std::vector<BlockStatistics>& per_tile);
  // From stored counts (a restarted server): per tile, per block; checked against the plan.
  static SampleAllocation from_counts(const RenderPlan& plan, std::vector<std::vector<PassSamples>> per_tile);

  int tile_count() const { return static_cast<int>(samples_.size()); }
  // Samples per pixel per pass after the pilot, per block, by parity (WorkUnit::samples).
  const std::vector<PassSamples>& tile(int t) const { return samples_[static_cast<std::size_t>(t)]; }
  // The mean samples per pixel after `passes` whole passes, over the tiles' pixels.
  double mean_samples_per_pixel(const RenderPlan& plan, int passes) const;
  // The fewest and most samples per pass of any block and parity.
  int min_samples_per_pass() const;
  int max_samples_per_pass() const;

 private:
  std::vector<std::vector<PassSamples>> samples_;  // [tile][block]
  std::vector<std::vector<PassSamples>> pixels_;   // [tile][block]: pixels of each parity
};

}  // namespace skyfarm
