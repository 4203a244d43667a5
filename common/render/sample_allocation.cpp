#include "common/render/sample_allocation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace skyfarm {

namespace {

// Pixels of each parity in every block of tile t (geometry only: never the
// samples, which must not steer the counts).
std::vector<PassSamples> block_pixels(const RenderPlan& plan, int t) {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan.tile_rect(t, &x0, &y0, &w, &h);
  std::vector<PassSamples> n(static_cast<std::size_t>(plan.block_count(t)));
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x) {
      PassSamples& b = n[static_cast<std::size_t>(plan.block_of(t, x, y))];
      ++(((x + y) & 1) != 0 ? b.odd : b.even);
    }
  return n;
}

// Samples per pass n_g = clamp(k s_g, lo, hi) for the groups g (pixel counts
// m_g, RMS s_g), with k such that sum m_g n_g = S sum m_g (bisection: the sum
// is monotone in k); before rounding.
std::vector<double> normalised_counts(const std::vector<double>& s, const std::vector<int>& m, double S) {
  const double lo = S / SampleAllocation::kMinRatio, hi = S * SampleAllocation::kMaxRatio;
  double sum_m = 0.0, sum_ms = 0.0;
  for (std::size_t g = 0; g < s.size(); ++g) {
    sum_m += m[g];
    sum_ms += m[g] * s[g];
  }
  if (!(sum_ms > 0.0)) return std::vector<double>(s.size(), S);  // a black image: uniform
  const double target = S * sum_m;
  auto total = [&](double k) {
    double t = 0.0;
    for (std::size_t g = 0; g < s.size(); ++g) t += m[g] * std::clamp(k * s[g], lo, hi);
    return t;
  };
  // Unclamped, k0 meets the target; the clamps move the solution by less
  // than the bracket's factor.
  const double k0 = target / sum_ms, wide = 16.0 * SampleAllocation::kMaxRatio;
  double a = k0 / wide, b = k0 * wide;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (a + b);
    (total(mid) < target ? a : b) = mid;
  }
  std::vector<double> n(s.size());
  for (std::size_t g = 0; g < s.size(); ++g) n[g] = std::clamp(0.5 * (a + b) * s[g], lo, hi);
  return n;
}

int& parity_member(PassSamples& p, int c) { return c == 0 ? p.even : p.odd; }
int parity_member(const PassSamples& p, int c) { return c == 0 ? p.even : p.odd; }

}  // namespace

// Per block and parity, sqrt(mean var(Y_mean)) over the pixels with an
// estimate.  All pilot pixels have the same sample count, so this is
// proportional to the RMS per-sample standard deviation.
SampleAllocation::BlockStatistics SampleAllocation::pilot_statistics(const RenderPlan& plan, int t,
                                                                     const FilmTile& tile,
                                                                     const std::vector<std::uint32_t>& excluded) {
  const std::size_t blocks = static_cast<std::size_t>(plan.block_count(t));
  std::vector<std::array<double, 2>> sum(blocks, {0.0, 0.0});
  std::vector<std::array<int, 2>> count(blocks, {0, 0});
  for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y)
    for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x) {
      const auto pixel =
          static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(plan.width) + static_cast<std::uint32_t>(x);
      if (std::binary_search(excluded.begin(), excluded.end(), pixel)) continue;
      const auto v = tile.luminance_variance_of_mean(x, y);
      if (!v) continue;
      const std::size_t b = static_cast<std::size_t>(plan.block_of(t, x, y)), c = static_cast<std::size_t>((x + y) & 1);
      sum[b][c] += *v;
      ++count[b][c];
    }
  BlockStatistics rms(blocks);
  for (std::size_t b = 0; b < blocks; ++b)
    for (std::size_t c = 0; c < 2; ++c)
      rms[b][c] = count[b][c] > 0 ? std::sqrt(sum[b][c] / count[b][c]) : std::numeric_limits<double>::quiet_NaN();
  return rms;
}

SampleAllocation SampleAllocation::from_pilot(const RenderPlan& plan, const std::vector<FilmTile>& pilot,
                                              const std::vector<std::uint32_t>& excluded) {
  std::vector<BlockStatistics> rms;
  for (std::size_t t = 0; t < pilot.size(); ++t)
    rms.push_back(pilot_statistics(plan, static_cast<int>(t), pilot[t], excluded));
  return from_statistics(plan, rms);
}

SampleAllocation SampleAllocation::from_statistics(const RenderPlan& plan,
                                                   const std::vector<BlockStatistics>& per_tile) {
  const int T = plan.tile_count(), S = plan.samples_per_pass;
  if (static_cast<int>(per_tile.size()) != T)
    throw std::invalid_argument("sample allocation: the pilot has " + std::to_string(per_tile.size()) +
                                " tiles, the plan " + std::to_string(T));
  SampleAllocation a;
  for (int t = 0; t < T; ++t) {
    a.pixels_.push_back(block_pixels(plan, t));
    a.samples_.emplace_back(a.pixels_.back().size(), PassSamples{S, S});
    if (per_tile[static_cast<std::size_t>(t)].size() != a.pixels_.back().size())
      throw std::invalid_argument("sample allocation: tile " + std::to_string(t) + " has statistics of " +
                                  std::to_string(per_tile[static_cast<std::size_t>(t)].size()) + " blocks");
  }
  // Pixels of parity c take their counts from the pilot of parity 1 - c only.
  for (int c = 0; c < 2; ++c) {
    std::vector<double> s;
    std::vector<int> m;
    std::vector<PassSamples*> out;
    for (std::size_t t = 0; t < per_tile.size(); ++t)
      for (std::size_t b = 0; b < per_tile[t].size(); ++b) {
        const double source = per_tile[t][b][static_cast<std::size_t>(1 - c)];
        const int count = parity_member(a.pixels_[t][b], c);
        if (std::isnan(source) || count == 0) continue;  // keeps S
        s.push_back(source);
        m.push_back(count);
        out.push_back(&a.samples_[t][b]);
      }
    const std::vector<double> n = normalised_counts(s, m, S);
    for (std::size_t g = 0; g < out.size(); ++g)
      parity_member(*out[g], c) = std::max(1, static_cast<int>(std::lround(n[g])));
  }
  return a;
}

SampleAllocation SampleAllocation::from_counts(const RenderPlan& plan, std::vector<std::vector<PassSamples>> per_tile) {
  if (static_cast<int>(per_tile.size()) != plan.tile_count())
    throw std::invalid_argument("sample allocation: counts for " + std::to_string(per_tile.size()) + " tiles, the plan has " +
                                std::to_string(plan.tile_count()));
  SampleAllocation a;
  for (int t = 0; t < plan.tile_count(); ++t) {
    const auto& blocks = per_tile[static_cast<std::size_t>(t)];
    if (static_cast<int>(blocks.size()) != plan.block_count(t))
      throw std::invalid_argument("sample allocation: tile " + std::to_string(t) + " has counts for " +
                                  std::to_string(blocks.size()) + " blocks");
    for (const PassSamples& p : blocks)
      if (p.even < 1 || p.odd < 1) throw std::invalid_argument("sample allocation: fewer than 1 sample per pass");
    a.pixels_.push_back(block_pixels(plan, t));
  }
  a.samples_ = std::move(per_tile);
  return a;
}

double SampleAllocation::mean_samples_per_pixel(const RenderPlan& plan, int passes) const {
  passes = std::clamp(passes, 0, plan.passes);
  if (passes == 0) return 0.0;
  double samples = 0.0, pixels = 0.0;
  const double pilot = plan.pass_end_sample(0) - plan.pass_first_sample(0);
  for (std::size_t t = 0; t < samples_.size(); ++t)
    for (std::size_t b = 0; b < samples_[t].size(); ++b)
      for (int c = 0; c < 2; ++c) {
        const int n = parity_member(samples_[t][b], c), m = parity_member(pixels_[t][b], c);
        double per_pixel = pilot;
        for (int p = 1; p < passes; ++p) per_pixel += plan.allocated_samples(p, n);
        samples += m * per_pixel;
        pixels += m;
      }
  return pixels > 0.0 ? samples / pixels : 0.0;
}

int SampleAllocation::min_samples_per_pass() const {
  int n = std::numeric_limits<int>::max();
  for (const auto& blocks : samples_)
    for (const PassSamples& p : blocks) n = std::min({n, p.even, p.odd});
  return n == std::numeric_limits<int>::max() ? 0 : n;
}

int SampleAllocation::max_samples_per_pass() const {
  int n = 0;
  for (const auto& blocks : samples_)
    for (const PassSamples& p : blocks) n = std::max({n, p.even, p.odd});
  return n;
}

}  // namespace skyfarm
