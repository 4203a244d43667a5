#include "common/lut/transmittance_lut.h"

#include <algorithm>
#include <cmath>

#include "common/core/math.h"
#include "common/lut/bilinear.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/shell_geometry.h"
#include "common/lut/simd_clones.h"

namespace skyfarm {

using lut::distance_to_top;

namespace {
// The nodes are equally spaced in v = 1 - (1 - x_mu)^(1/4) (mu_position, in
// the header: two square roots, cheaper in the look-ups than a cube root).
double x_mu_from_v(double v) { return 1.0 - sqr(sqr(1.0 - v)); }
}  // namespace

TransmittanceLut TransmittanceLut::build(const MediumTable& medium, int mu_samples, int r_samples, int steps) {
  if (mu_samples < 2 || r_samples < 2 || steps < 2)
    throw lut::invalid_argument("transmittance LUT: need >= 2 samples and steps, got ", mu_samples, ", ", r_samples,
                                ", ", steps);
  TransmittanceLut t;
  t.bins_ = medium.bins();
  t.n_mu_ = mu_samples;
  t.n_r_ = r_samples;
  t.steps_ = steps + (steps % 2);  // Simpson's rule: an even count
  t.R_ = medium.planet_radius_m();
  t.R_top_ = medium.top_radius_m();
  t.H_ = std::sqrt((t.R_top_ - t.R_) * (t.R_top_ + t.R_));
  const std::size_t B = static_cast<std::size_t>(t.bins_);
  t.values_.assign(static_cast<std::size_t>(mu_samples) * static_cast<std::size_t>(r_samples) * B, 0.0);
  std::vector<double> tau(B);
  for (int j = 0; j < r_samples; ++j)
    for (int i = 0; i < mu_samples; ++i) {
      double r, mu;
      t.r_mu_from_unit(static_cast<double>(j) / (r_samples - 1), x_mu_from_v(static_cast<double>(i) / (mu_samples - 1)),
                       &r, &mu);
      optical_depth_to_top(medium, r, mu, t.steps_, tau.data());
      double* out = t.values_.data() + (static_cast<std::size_t>(j) * mu_samples + i) * B;
      for (std::size_t b = 0; b < B; ++b) out[b] = std::exp(-tau[b]);
    }
  return t;
}

// Bruneton 2017, GetTransmittanceTextureUvFromRMu (without the half-texel
// offsets: our values sit on the nodes).
void TransmittanceLut::unit_from_r_mu(double r, double mu, double* x_r, double* x_mu) const {
  r = std::clamp(r, R_, R_top_);
  const double rho = std::sqrt((r - R_) * (r + R_));
  const double d = distance_to_top(r, mu, R_top_);
  const double d_min = R_top_ - r, d_max = rho + H_;
  *x_r = rho / H_;
  *x_mu = std::clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
}

// Bruneton 2017, GetRMuFromTransmittanceTextureUv: r from rho, then mu from
// the law of cosines on the triangle (centre, point, exit point):
// R_top^2 = r^2 + d^2 + 2 r d mu  =>  mu = (H^2 - rho^2 - d^2) / (2 r d).
void TransmittanceLut::r_mu_from_unit(double x_r, double x_mu, double* r, double* mu) const {
  const double rho = H_ * x_r;
  *r = std::sqrt(rho * rho + R_ * R_);
  const double d_min = R_top_ - *r, d_max = rho + H_;
  const double d = d_min + x_mu * (d_max - d_min);
  *mu = d == 0.0 ? 1.0 : std::clamp((H_ * H_ - rho * rho - d * d) / (2.0 * *r * d), -1.0, 1.0);
}

TransmittanceLut::RadiusCoord TransmittanceLut::locate_r(double r) const {
  RadiusCoord rc;
  rc.r = std::clamp(r, R_, R_top_);
  rc.r2 = rc.r * rc.r;
  rc.top_c = (R_top_ - rc.r) * (R_top_ + rc.r);
  rc.ground_c = (rc.r - R_) * (rc.r + R_);
  const double rho = std::sqrt(rc.ground_c);
  rc.d_min = R_top_ - rc.r;
  rc.inv_range = 1.0 / (rho + H_ - rc.d_min);  // d_max - d_min >= H - (R_top - R) > 0
  const double u = std::clamp(rho / H_, 0.0, 1.0) * (n_r_ - 1);
  const std::size_t j = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(n_r_ - 2));
  rc.row = j * static_cast<std::size_t>(n_mu_) * static_cast<std::size_t>(bins_);
  rc.fj = u - static_cast<double>(j);
  return rc;
}

void TransmittanceLut::lookup(const RadiusCoord& rc, double u, double* out) const {
  if (u < 0.0) {
    std::fill(out, out + bins_, 0.0);
    return;
  }
  bilinear(rc, u).eval(bins_, out);
}

void TransmittanceLut::lookup_weighted_add(const RadiusCoord& rc, double u, const double* weight, double* acc) const {
  if (u < 0.0) return;
  bilinear(rc, u).weighted_add(bins_, weight, acc);
}

// tau = int sigma_t ds over each monotone part, s = s_a + (s_b - s_a) u^2,
// ds = 2 (s_b - s_a) u du, Simpson's rule in u (weights 1, 4, 2, ..., 4, 1
// times 1/(3n)).
SKYFARM_LUT_SIMD_CLONES
void TransmittanceLut::optical_depth_to_top(const MediumTable& medium, double r, double mu, int steps, double* tau) {
  const int B = medium.bins();
  const double R = medium.planet_radius_m(), R_top = medium.top_radius_m();
  std::fill(tau, tau + B, 0.0);
  r = std::clamp(r, R, R_top);
  const double l = r * std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
  const double s0 = r * mu;
  const double s_top = std::sqrt(std::max(0.0, (R_top - l) * (R_top + l)));
  const int n = steps + (steps % 2);
  auto part = [&](double a, double b) {
    if (!(b > a)) return;
    for (int k = 1; k <= n; ++k) {  // k = 0 has ds/du = 0
      const double u = static_cast<double>(k) / n;
      const double s = a + (b - a) * u * u;
      const double simpson = (k == n ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0)) / (3.0 * n);
      const double w = simpson * 2.0 * (b - a) * u;
      const double h = std::sqrt(l * l + s * s) - R;
      medium.add_sigma_t(medium.locate(h), w, tau);
    }
  };
  if (s0 < 0.0) {  // descends to the closest approach first: two ascending parts in |s|
    part(0.0, -s0);
    part(0.0, s_top);
  } else {
    part(s0, s_top);
  }
}

}  // namespace skyfarm
