#include "common/spectrum/color.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/core/constants.h"
#include "common/spectrum/cie_observer.h"

namespace skyfarm {

// x = X/(X+Y+Z), y = Y/(X+Y+Z) (CIE 15:2004 §7.3); (0, 0) for black.
Chromaticity chromaticity(const Xyz& c) {
  const double sum = c.x + c.y + c.z;
  if (sum == 0.0) return {0.0, 0.0};
  return {c.x / sum, c.y / sum};
}

// IEC 61966-2-1:1999 §5.2: V = 12.92 L (L ≤ 0.0031308), 1.055 L^(1/2.4) − 0.055 otherwise.
double srgb_encode(double linear) {
  if (linear <= 0.0031308) return 12.92 * linear;
  return 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

// IEC 61966-2-1:1999 §5.2: L = V/12.92 (V ≤ 0.04045), ((V + 0.055)/1.055)^2.4 otherwise.
double srgb_decode(double encoded) {
  if (encoded <= 0.04045) return encoded / 12.92;
  return std::pow((encoded + 0.055) / 1.055, 2.4);
}

// (X, Y, Z) = K_m (1/N) Σ_i (x̄, ȳ, z̄)(λ_i) L_i / p(λ_i)  (pbrt-v4 SampledSpectrum::ToXYZ, absolute).
Xyz spectral_sample_to_xyz(const SampledWavelengths& lambda, const std::array<double, kWavelengthsPerPath>& L) {
  Xyz sum{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < L.size(); ++i) {
    const double pdf = lambda.pdf[i];
    if (!(pdf > 0.0)) continue;  // a terminated or impossible wavelength carries nothing
    const Xyz cmf = cie1931_cmf(lambda.lambda_nm[i]);
    const double w = L[i] / pdf;
    sum.x += cmf.x * w;
    sum.y += cmf.y * w;
    sum.z += cmf.z * w;
  }
  const double scale = kMaxLuminousEfficacy / kWavelengthsPerPath;
  return {sum.x * scale, sum.y * scale, sum.z * scale};
}

// (X, Y, Z) = K_m ∫ (x̄, ȳ, z̄) L dλ over the observer's 360–830 nm: on every
// interval between consecutive knots of the merged grid (CMF knots ∪ L's
// knots) both factors are linear, so Simpson's rule
//   ∫_p^q f g dλ = (q − p)/6 [f g(p) + 4 f g(m) + f g(q)],  m = (p + q)/2,
// is exact.  Each interval lies wholly inside or wholly outside L's knot span;
// outside it L is constant (0 or its end value), evaluated at m.
Xyz spectrum_to_xyz(const PiecewiseLinear& L) {
  const CieObserver& o = cie1931_observer();
  const double lo = o.ybar.x_min(), hi = o.ybar.x_max();
  std::vector<double> grid(o.ybar.x().begin(), o.ybar.x().end());
  for (double x : L.x())
    if (x > lo && x < hi) grid.push_back(x);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());

  const bool single_knot = L.x().size() == 1;
  Xyz sum{0.0, 0.0, 0.0};
  for (std::size_t k = 1; k < grid.size(); ++k) {
    const double p = grid[k - 1], q = grid[k], m = 0.5 * (p + q);
    const bool inside = !single_knot && m > L.x_min() && m < L.x_max();
    const double Lp = inside ? L(p) : L(m), Lm = L(m), Lq = inside ? L(q) : L(m);
    const double w = (q - p) / 6.0;
    sum.x += w * (o.xbar(p) * Lp + 4.0 * o.xbar(m) * Lm + o.xbar(q) * Lq);
    sum.y += w * (o.ybar(p) * Lp + 4.0 * o.ybar(m) * Lm + o.ybar(q) * Lq);
    sum.z += w * (o.zbar(p) * Lp + 4.0 * o.zbar(m) * Lm + o.zbar(q) * Lq);
  }
  return {kMaxLuminousEfficacy * sum.x, kMaxLuminousEfficacy * sum.y, kMaxLuminousEfficacy * sum.z};
}

// Y = K_m ∫ ȳ(λ) L(λ) dλ, cd/m² (CIE 15:2004 §7.1).
double luminance_cd_m2(const PiecewiseLinear& L) { return spectrum_to_xyz(L).y; }

}  // namespace skyfarm
