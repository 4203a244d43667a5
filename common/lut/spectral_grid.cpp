#include "common/lut/spectral_grid.h"

#include <algorithm>
#include <cmath>

#include "common/core/constants.h"
#include "common/lut/invalid_argument.h"
#include "common/spectrum/cie_observer.h"

namespace skyfarm {
namespace {

// A binned spectrum's reconstruction at lambda as (1 - f) L[i0] + f L[i1].
struct Hat {
  int i0, i1;
  double f;
};

Hat locate(const SpectralGrid& g, double lambda) {
  const int n = g.size();
  const double u = (lambda - g.lambda_min_nm()) / g.width_nm() - 0.5;  // in units of bins from centre 0
  if (n == 1 || u <= 0.0) return {0, 0, 0.0};
  if (u >= n - 1) return {n - 1, n - 1, 0.0};
  const int i = std::min(static_cast<int>(u), n - 2);
  return {i, i + 1, u - i};
}

}  // namespace

SpectralGrid::SpectralGrid(double lambda_min_nm, double lambda_max_nm, int bins)
    : lambda_min_(lambda_min_nm), lambda_max_(lambda_max_nm) {
  if (bins < 1) throw lut::invalid_argument("spectral grid: bins must be >= 1, got ", bins);
  if (!(std::isfinite(lambda_min_nm) && std::isfinite(lambda_max_nm) && lambda_min_nm > 0.0 &&
        lambda_max_nm > lambda_min_nm))
    throw lut::invalid_argument("spectral grid: need 0 < lambda_min < lambda_max, got [", lambda_min_nm, ", ",
                                lambda_max_nm, "]");
  width_ = (lambda_max_ - lambda_min_) / bins;
  centres_.resize(static_cast<std::size_t>(bins));
  for (int i = 0; i < bins; ++i) centres_[static_cast<std::size_t>(i)] = lambda_min_ + (i + 0.5) * width_;
}

// (1/w) int_a^b f: trapezoids on the 0.25 nm lattice plus the partial end pieces.
double SpectralGrid::bin_mean(const std::function<double(double)>& f, int i) const {
  const double a = lambda_min_ + i * width_, b = a + width_;
  constexpr double kStep = 0.25;
  double x0 = a, f0 = f(a), sum = 0.0;
  for (double k = std::floor(a / kStep) + 1.0; k * kStep < b; k += 1.0) {
    const double x1 = k * kStep, f1 = f(x1);
    sum += 0.5 * (f0 + f1) * (x1 - x0);
    x0 = x1;
    f0 = f1;
  }
  sum += 0.5 * (f0 + f(b)) * (b - x0);
  return sum / width_;
}

double SpectralGrid::reconstruct(std::span<const double> values, double lambda_nm) const {
  const Hat h = locate(*this, lambda_nm);
  return (1.0 - h.f) * values[static_cast<std::size_t>(h.i0)] + h.f * values[static_cast<std::size_t>(h.i1)];
}

// On every interval [p, q] between consecutive knots of (CIE knots U bin
// centres U {lo, hi}) both the CMF and the reconstruction are linear, so
// (color.cpp spectrum_to_xyz, the same argument)
//   int_p^q cmf L = (q - p)/6 [cmf L (p) + 4 cmf L (m) + cmf L (q)],  m = (p + q)/2,
// exactly; L at each of the three points is a combination of two bins,
// whose coefficients accumulate into the weights.
BinnedSpectrumIntegral::BinnedSpectrumIntegral(const SpectralGrid& grid, double lo_nm, double hi_nm) {
  const double lo = std::max(lo_nm, grid.lambda_min_nm()), hi = std::min(hi_nm, grid.lambda_max_nm());
  if (!(lo < hi)) throw lut::invalid_argument("binned spectrum integral: empty range [", lo_nm, ", ", hi_nm, "]");
  const std::size_t n = static_cast<std::size_t>(grid.size());
  wx_.assign(n, 0.0);
  wy_.assign(n, 0.0);
  wz_.assign(n, 0.0);
  wmean_.assign(n, 0.0);

  const CieObserver& o = cie1931_observer();
  std::vector<double> knots = {lo, hi};
  for (double x : o.ybar.x())
    if (x > lo && x < hi) knots.push_back(x);
  for (double x : grid.centres_nm())
    if (x > lo && x < hi) knots.push_back(x);
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());

  // The CMFs are zero outside their table (a jump at its ends): intervals
  // outside it carry only the band-mean weight.
  const double cmf_lo = o.ybar.x_min(), cmf_hi = o.ybar.x_max();
  auto add = [&](double lambda, double simpson_weight, bool in_cmf) {
    const Hat h = locate(grid, lambda);
    const Xyz c = in_cmf ? cie1931_cmf(lambda) : Xyz{0.0, 0.0, 0.0};
    for (const auto& [i, a] : {std::pair{h.i0, 1.0 - h.f}, std::pair{h.i1, h.f}}) {
      const std::size_t k = static_cast<std::size_t>(i);
      const double w = simpson_weight * a;
      wx_[k] += kMaxLuminousEfficacy * c.x * w;
      wy_[k] += kMaxLuminousEfficacy * c.y * w;
      wz_[k] += kMaxLuminousEfficacy * c.z * w;
      wmean_[k] += w / (hi - lo);
    }
  };
  for (std::size_t k = 1; k < knots.size(); ++k) {
    const double p = knots[k - 1], q = knots[k], w = (q - p) / 6.0;
    const bool in_cmf = p >= cmf_lo && q <= cmf_hi;
    add(p, w, in_cmf);
    add(0.5 * (p + q), 4.0 * w, in_cmf);
    add(q, w, in_cmf);
  }
}

Xyz BinnedSpectrumIntegral::xyz(std::span<const double> values) const {
  Xyz c{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < wx_.size(); ++i) {
    c.x += wx_[i] * values[i];
    c.y += wy_[i] * values[i];
    c.z += wz_[i] * values[i];
  }
  return c;
}

double BinnedSpectrumIntegral::band_mean(std::span<const double> values) const {
  double s = 0.0;
  for (std::size_t i = 0; i < wmean_.size(); ++i) s += wmean_[i] * values[i];
  return s;
}

}  // namespace skyfarm
