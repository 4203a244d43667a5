// Variance-aware sample allocation (common/render/sample_allocation.h):
// counts proportional to the pilot's noise within the clamps, the same mean
// samples per pixel, a pixel's count never taken from its own parity's
// pilot (the property that keeps the image unbiased), and an adaptive render
// that agrees with the uniform one within its standard error.
#include "common/render/sample_allocation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "api/render_spec.h"
#include "common/render/local_render.h"

namespace skyfarm {
namespace {

// 64 x 32 pixels, two 32-pixel tiles of 4 x 4 blocks, 16 samples per pass, 4 passes.
RenderPlan small_plan() { return make_render_plan(64, 32, 360.0, 830.0, 1, 64, 1, 32, 16); }

// A pilot whose pixel (x, y) has per-sample luminance mean 1 and standard
// deviation sigma(x, y): 16 samples 1 +- sigma.
std::vector<FilmTile> pilot_of(const RenderPlan& plan, const std::function<double(int, int)>& sigma) {
  std::vector<FilmTile> tiles;
  for (int t = 0; t < plan.tile_count(); ++t) {
    int x0 = 0, y0 = 0, w = 0, h = 0;
    plan.tile_rect(t, &x0, &y0, &w, &h);
    FilmTile tile(x0, y0, w, h, 1);
    for (int y = y0; y < y0 + h; ++y)
      for (int x = x0; x < x0 + w; ++x)
        for (int s = 0; s < plan.samples_per_pass; ++s) {
          const double Y = 1.0 + (s % 2 == 0 ? 1.0 : -1.0) * sigma(x, y);
          tile.add_sample(x, y, 0, Xyz{Y, Y, Y}, Y);
        }
    tiles.push_back(std::move(tile));
  }
  return tiles;
}

TEST(SampleAllocation, APixelsCountComesFromTheOtherParitysPilotOnly) {
  const RenderPlan plan = small_plan();
  auto base = [](int x, int y) { return 0.1 + 0.01 * ((x * 7 + y * 3) % 11); };
  // The even pixels' pilot changed wildly, the odd pixels' kept.
  auto even_changed = [&](int x, int y) { return ((x + y) & 1) == 0 ? 0.5 * ((x * y) % 5) : base(x, y); };
  const SampleAllocation a = SampleAllocation::from_pilot(plan, pilot_of(plan, base), {});
  const SampleAllocation b = SampleAllocation::from_pilot(plan, pilot_of(plan, even_changed), {});
  int odd_changed = 0;
  for (int t = 0; t < plan.tile_count(); ++t)
    for (std::size_t k = 0; k < a.tile(t).size(); ++k) {
      EXPECT_EQ(a.tile(t)[k].even, b.tile(t)[k].even) << "tile " << t << " block " << k;
      odd_changed += a.tile(t)[k].odd != b.tile(t)[k].odd;
    }
  EXPECT_GT(odd_changed, 8) << "the odd pixels' counts follow the even pixels' pilot";
}

TEST(SampleAllocation, CountsFollowTheNoiseWithinTheClampsAndKeepTheMean) {
  const RenderPlan plan = small_plan();
  ASSERT_EQ(plan.tile_count(), 2);
  ASSERT_EQ(plan.block_count(0), 16);
  // Left tile sigma 1, right tile 2, and one block of the right tile 100 (clamped).
  auto sigma = [&](int x, int y) { return x < 32 ? 1.0 : (x >= 56 && y >= 24 ? 100.0 : 2.0); };
  const SampleAllocation a = SampleAllocation::from_pilot(plan, pilot_of(plan, sigma), {});
  const PassSamples left = a.tile(0)[0], right = a.tile(1)[0], loud = a.tile(1)[15];
  EXPECT_EQ(left.even, left.odd);
  EXPECT_NEAR(static_cast<double>(right.even) / left.even, 2.0, 0.15) << left.even << " vs " << right.even;
  EXPECT_EQ(loud.even, 16 * 4) << "at most kMaxRatio times the uniform 16";
  EXPECT_EQ(a.max_samples_per_pass(), 64);
  // 16 per pass on average: 64 in all after 4 passes (to the rounding of each block's count).
  EXPECT_NEAR(a.mean_samples_per_pixel(plan, 4), 64.0, 0.02 * 64.0);
  EXPECT_DOUBLE_EQ(a.mean_samples_per_pixel(plan, 1), 16.0) << "the pilot is uniform";
}

TEST(SampleAllocation, ANoiselessPilotIsUniformAndSunPixelsAreLeftOut) {
  const RenderPlan plan = small_plan();
  const SampleAllocation black = SampleAllocation::from_pilot(plan, pilot_of(plan, [](int, int) { return 0.0; }), {});
  EXPECT_EQ(black.min_samples_per_pass(), 16);
  EXPECT_EQ(black.max_samples_per_pass(), 16);
  // One pixel (the sun disk's) a million times noisier: excluded, it changes nothing.
  auto with_sun = [](int x, int y) { return x == 40 && y == 9 ? 1e6 : 1.0; };
  const std::vector<std::uint32_t> sun{9 * 64 + 40};
  const SampleAllocation a = SampleAllocation::from_pilot(plan, pilot_of(plan, with_sun), sun);
  EXPECT_EQ(a.min_samples_per_pass(), 16);
  EXPECT_EQ(a.max_samples_per_pass(), 16);
}

TEST(SampleAllocation, StoredCountsAreCheckedAgainstThePlan) {
  const RenderPlan plan = small_plan();
  std::vector<std::vector<PassSamples>> ok(2, std::vector<PassSamples>(16, PassSamples{3, 40}));
  const SampleAllocation a = SampleAllocation::from_counts(plan, ok);
  EXPECT_EQ(a.tile(1)[5], (PassSamples{3, 40}));
  EXPECT_THROW(SampleAllocation::from_counts(plan, {ok[0]}), std::invalid_argument);
  auto short_tile = ok;
  short_tile[1].pop_back();
  EXPECT_THROW(SampleAllocation::from_counts(plan, short_tile), std::invalid_argument);
  auto zero = ok;
  zero[0][2].odd = 0;
  EXPECT_THROW(SampleAllocation::from_counts(plan, zero), std::invalid_argument);
}

TEST(SampleAllocation, LaterPassesContinueThePilotsSamplesWithoutOverlap) {
  const RenderPlan plan = make_render_plan(64, 32, 360.0, 830.0, 1, 40, 1, 32, 16);  // passes of 16, 16, 8
  ASSERT_EQ(plan.passes, 3);
  WorkUnit u{1, 0, 0, std::vector<PassSamples>(16, PassSamples{5, 30})};
  int first = 0, end = 0;
  plan.sample_range(u, 33, 0, &first, &end);  // pass 0: uniform whatever the counts
  EXPECT_EQ(first, 0);
  EXPECT_EQ(end, 16);
  u.pass = 1;
  plan.sample_range(u, 33, 0, &first, &end);  // odd pixel
  EXPECT_EQ(first, 16);
  EXPECT_EQ(end, 46);
  plan.sample_range(u, 34, 0, &first, &end);  // even pixel
  EXPECT_EQ(first, 16);
  EXPECT_EQ(end, 21);
  u.pass = 2;  // the short last pass: half of n, rounded
  plan.sample_range(u, 34, 0, &first, &end);
  EXPECT_EQ(first, 21);
  EXPECT_EQ(end, 24);
  plan.sample_range(u, 33, 0, &first, &end);
  EXPECT_EQ(first, 46);
  EXPECT_EQ(end, 61);
  // Blocks: pixel (41, 17) of tile 1 (x0 = 32) is in block row 2, column 1.
  EXPECT_EQ(plan.block_of(1, 41, 17), 2 * 4 + 1);
}

// Image mean luminance and its standard error, from the last pass's film.
struct ImageMean {
  double mean = 0.0, standard_error = 0.0;
  std::uint64_t rejected = 0;
};

ImageMean render_mean(const char* request_json, int threads, ProgressiveResult* out = nullptr) {
  const RenderSetup setup = make_render_setup(api::render_spec(api::parse_render_request(request_json)));
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  ImageMean m;
  StopCriteria stop;
  stop.after_pass = [&](int pass, const std::vector<FilmTile>& film, double) {
    if (pass != setup.plan.passes) return;
    double sum = 0.0, var = 0.0;
    int n = 0;
    for (const FilmTile& tile : film) {
      m.rejected += tile.rejected_samples();
      for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y)
        for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x) {
          const auto Y = tile.mean_xyz(x, y);
          const auto v = tile.luminance_variance_of_mean(x, y);
          if (!Y || !v) continue;
          sum += Y->y;
          var += *v;
          ++n;
        }
    }
    m.mean = sum / n;
    m.standard_error = std::sqrt(var) / n;
  };
  Image image(setup.plan.width, setup.plan.height);
  const ProgressiveResult r = render_image_progressive(renderer, &image, threads, stop);
  if (out) *out = r;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const double Y = image.luminance(x, y);
      EXPECT_TRUE(std::isfinite(Y) && Y >= 0.0) << x << "," << y;
    }
  return m;
}

// A sunset (sun at 88 deg), where the noise differs most between blocks.
constexpr const char* kUniform = R"({"sun": {"zenith_deg": 88, "azimuth_deg": 100},
  "camera": {"projection": "equirectangular", "width": 64, "height": 32},
  "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 64}, "seed": 5})";
constexpr const char* kAdaptive = R"({"sun": {"zenith_deg": 88, "azimuth_deg": 100},
  "camera": {"projection": "equirectangular", "width": 64, "height": 32},
  "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 64, "adaptive": true}, "seed": 5})";

TEST(AdaptiveRender, AgreesWithTheUniformRenderAndDoesNotDependOnThreads) {
  ProgressiveResult r;
  const ImageMean adaptive = render_mean(kAdaptive, 2, &r);
  const ImageMean uniform = render_mean(kUniform, 2);
  ASSERT_TRUE(r.allocation.has_value());
  EXPECT_LT(r.allocation->min_samples_per_pass(), r.allocation->max_samples_per_pass());
  EXPECT_NEAR(r.samples_per_pixel, 64.0, 2.0);
  EXPECT_EQ(adaptive.rejected, 0u);
  const double se = std::hypot(adaptive.standard_error, uniform.standard_error);
  EXPECT_LT(std::abs(adaptive.mean - uniform.mean), 4.0 * se)
      << adaptive.mean << " vs " << uniform.mean << " (standard error " << se << ")";
  const ImageMean one_thread = render_mean(kAdaptive, 1);
  EXPECT_EQ(one_thread.mean, adaptive.mean) << "the allocation and the samples do not depend on the threads";
  EXPECT_EQ(one_thread.standard_error, adaptive.standard_error);
}

}  // namespace
}  // namespace skyfarm
