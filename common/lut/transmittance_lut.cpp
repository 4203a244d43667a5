#include "common/lut/transmittance_lut.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <span>
#include <type_traits>
#include <vector>

#include "common/core/math.h"
#include "common/lut/bilinear.h"
#include "common/lut/invalid_argument.h"
#include "common/lut/shell_geometry.h"
#include "common/lut/simd_clones.h"
#include "common/lut/vector_math.h"

namespace skyfarm {

using lut::distance_to_top;

namespace {
constexpr std::size_t kDefaultBins = kDefaultLutBins;

// The nodes are equally spaced in v = 1 - (1 - x_mu)^(1/4) (mu_position, in
// the header: two square roots, cheaper in the look-ups than a cube root).
double x_mu_from_v(double v) { return 1.0 - sqr(sqr(1.0 - v)); }

// The optical depth quadrature (header): per monotone part [s_a, s_b] the
// samples s = s_a + (s_b - s_a) u_k^2, k = 1..n, with weights
// (s_b - s_a) weight_k, weight_k = Simpson's 1, 4, 2, ..., 4, 1 / (3 n)
// times ds/du / (s_b - s_a) = 2 u_k.  The sums run over the medium's
// extinction terms (medium_table.h), not over the bins: 8 values per sample
// for the Earth instead of 32 bins.
class OpticalDepthQuadrature {
 public:
  OpticalDepthQuadrature(const MediumTable& medium, int steps)
      : medium_(medium), n_(steps + (steps % 2)), u2_(n_), frac_(n_), weight_(n_), node_(n_), w0_(n_), w1_(n_) {
    for (int k = 1; k <= n_; ++k) {  // k = 0 has ds/du = 0
      const double u = static_cast<double>(k) / n_;
      const std::size_t j = static_cast<std::size_t>(k - 1);
      u2_[j] = static_cast<float>(u * u);
      weight_[j] = (k == n_ ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0)) / (3.0 * n_) * 2.0 * u;
    }
  }

  // The terms of every horizontal ray from the medium's altitude nodes to the
  // top (tangent_table, below), for the second part of descending rays.
  // mirror: a descending ray's optical depth as 2 tau_h(l) - its mirror
  // image's (the ray from r along -mu, which climbs from r to the top on the
  // same line), for rows whose rays from r are thin (climb_rule, below).
  void use_tangent_table(const std::vector<double>* tangent, bool mirror) {
    tangent_ = tangent;
    mirror_ = mirror;
  }

  // terms[k] = the tangent table at closest approach l (linear in altitude).
  [[gnu::always_inline]] void tangent_terms(double l, double* terms) const {
    std::fill(terms, terms + medium_.padded_terms(), 0.0);
    add_tangent(l, terms);
  }

  // terms[k] = int rho_k ds from radius r along mu to the top (rays into the
  // ground as if the planet were absent), k < medium.padded_terms().
  [[gnu::always_inline]] void terms_to_top(double r, double mu, double* terms) {
    const double R = medium_.planet_radius_m(), R_top = medium_.top_radius_m();
    std::fill(terms, terms + medium_.padded_terms(), 0.0);
    r = std::clamp(r, R, R_top);
    const double l = r * std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
    const double s0 = r * mu;
    const double s_top = std::sqrt(std::max(0.0, (R_top - l) * (R_top + l)));
    // A ray that descends to the closest approach first has two ascending
    // parts in |s|; the second is the horizontal ray from the closest
    // approach, from the tangent table when there is one.  (One call site in
    // a loop: with a = 0 as a constant, GCC specialises add_part and leaves
    // that copy's loop scalar.)
    const bool descends = s0 < 0.0, mirror = descends && tangent_ && mirror_;
    const double from[2] = {mirror ? -s0 : std::max(s0, 0.0), 0.0}, to[2] = {descends && !mirror ? -s0 : s_top, s_top};
    for (int part = 0; part < (descends && !tangent_ ? 2 : 1); ++part) add_part(l, from[part], to[part], terms);
    if (mirror) {
      // 2 tau_h(l) - (r to the top), each term >= tau_h(l) >= 0 exactly; the
      // max guards the rounding of terms that vanish.
      combine_tangent(l, terms, [](double climb, double tau_h) { return std::max(0.0, 2.0 * tau_h - climb); });
    } else if (descends && tangent_) {
      add_tangent(l, terms);
    }
  }

  // tau[b] from the terms.
  [[gnu::always_inline]] void expand(const double* terms, double* tau) const {
    if (static_cast<std::size_t>(medium_.bins()) == kDefaultBins) return expand_default(terms, tau);
    const std::size_t B = static_cast<std::size_t>(medium_.bins());
    const double* spectra = medium_.term_spectra();
    std::fill(tau, tau + B, 0.0);
    for (std::size_t k = 0; k < static_cast<std::size_t>(medium_.term_count()); ++k) {
      const double t = terms[k];
      const double* kappa = spectra + k * B;
      for (std::size_t b = 0; b < B; ++b) tau[b] += t * kappa[b];
    }
  }

 private:
  // terms[k] = combine(terms[k], the tangent table at closest approach l,
  // linear in altitude).
  template <class Combine>
  [[gnu::always_inline]] void combine_tangent(double l, double* terms, Combine combine) const {
    const std::size_t K = static_cast<std::size_t>(medium_.padded_terms());
    const MediumTable::Node node = medium_.locate(l - medium_.planet_radius_m());
    const double* a = tangent_->data() + node.i * K;
    const double f = node.f, g = 1.0 - f;
    for (std::size_t k = 0; k < K; ++k) terms[k] = combine(terms[k], g * a[k] + f * a[K + k]);
  }
  [[gnu::always_inline]] void add_tangent(double l, double* terms) const {
    combine_tangent(l, terms, [](double t, double tau_h) { return t + tau_h; });
  }

  // One part at distances [a, b] past the closest approach (radius l): the
  // samples' altitude nodes and weights in one vectorisable pass, then the
  // terms' profiles interpolated and summed.
  [[gnu::always_inline]] void add_part(double l, double a, double b, double* terms) {
    if (!(b > a)) return;
    const double R = medium_.planet_radius_m(), inv_dh = 1.0 / medium_.altitude_step_m();
    const double top_node = medium_.altitude_samples() - 1;
    const int last_cell = medium_.altitude_samples() - 2;
    const double d = b - a, l2 = l * l;
    // The altitudes in single precision (16 per AVX-512 instruction), without
    // the cancellation of sqrt(l^2 + s^2) - R: with e = s - a = d u^2,
    //   h = (r_a^2 - R^2 + e (2 a + e)) / (sqrt(l^2 + s^2) + R),
    // r_a^2 - R^2 = l^2 + a^2 - R^2 in double once per part, and every other
    // term a sum of non-negative numbers or a ratio (relative error ~1e-7:
    // 1 cm at 100 km, against 49 m between the medium's nodes).
    const float c_a = static_cast<float>((l2 + a * a) - R * R), two_a = static_cast<float>(2.0 * a);
    const float df = static_cast<float>(d), af = static_cast<float>(a), l2f = static_cast<float>(l2);
    const float Rf = static_cast<float>(R), inv_dhf = static_cast<float>(inv_dh), top = static_cast<float>(top_node);
    // (Locals, not members, in the loops: the compiler cannot prove that the
    // stores leave *this alone, and would not vectorise.)
    const std::size_t n = static_cast<std::size_t>(n_);
    const float* u2 = u2_.data();
    const double* weight = weight_.data();
    int* __restrict node = node_.data();
    float* __restrict frac = frac_.data();
    for (std::size_t k = 0; k < n; ++k) {
      const float e = df * u2[k], s = af + e;
      const float h = (c_a + e * (two_a + e)) / (std::sqrt(l2f + s * s) + Rf);
      const float x = std::min(std::max(h * inv_dhf, 0.0f), top);  // MediumTable::locate
      const int i = std::min(static_cast<int>(x), last_cell);
      node[k] = i;
      frac[k] = x - static_cast<float>(i);
    }
    double *__restrict w0 = w0_.data(), *__restrict w1 = w1_.data();
    for (std::size_t k = 0; k < n; ++k) {
      const double f = frac[k], w = d * weight[k];
      w0[k] = w * (1.0 - f);
      w1[k] = w * f;
    }
    // Eight terms at a time (one 64-byte block of the medium's profiles), in
    // two accumulators, the even and the odd samples (n is even), so that a
    // sample's add does not wait for the previous one's: with one, the add's
    // latency bounded the loop.  (GCC's vector extension: plain loops over
    // eight doubles were vectorised with shuffles.  Element-wise, so every
    // clone gives the same bits.)
    using Eight = double __attribute__((vector_size(64)));
    const std::size_t K = static_cast<std::size_t>(medium_.padded_terms());
    for (std::size_t c = 0; c < K; c += 8) {
      Eight even, odd = {};
      std::memcpy(&even, terms + c, sizeof even);
      for (std::size_t k = 0; k < n; k += 2) {
        const Eight* p = reinterpret_cast<const Eight*>(medium_.term_block(static_cast<std::size_t>(node[k]), c));
        const Eight* q = reinterpret_cast<const Eight*>(medium_.term_block(static_cast<std::size_t>(node[k + 1]), c));
        const std::size_t next = K / 8;  // the next node's block
        even += w0[k] * p[0] + w1[k] * p[next];
        odd += w0[k + 1] * q[0] + w1[k + 1] * q[next];
      }
      even += odd;
      std::memcpy(terms + c, &even, sizeof even);
    }
  }

  // expand() at the default bin count: the 32 sums in four vector
  // registers over the terms (a loop over memory made each term wait for the
  // previous term's store), the same products and order of additions.
  [[gnu::always_inline]] void expand_default(const double* terms, double* tau) const {
    using Eight = double __attribute__((vector_size(64)));
    const double* kappa = medium_.term_spectra();
    Eight t0 = {}, t1 = {}, t2 = {}, t3 = {}, k0, k1, k2, k3;
    const std::size_t K = static_cast<std::size_t>(medium_.term_count());
    for (std::size_t k = 0; k < K; ++k, kappa += kDefaultBins) {
      // (memcpy: the spectra are not 64-byte aligned.)
      std::memcpy(&k0, kappa, sizeof k0);
      std::memcpy(&k1, kappa + 8, sizeof k1);
      std::memcpy(&k2, kappa + 16, sizeof k2);
      std::memcpy(&k3, kappa + 24, sizeof k3);
      const double t = terms[k];
      t0 += t * k0;
      t1 += t * k1;
      t2 += t * k2;
      t3 += t * k3;
    }
    std::memcpy(tau, &t0, sizeof t0);
    std::memcpy(tau + 8, &t1, sizeof t1);
    std::memcpy(tau + 16, &t2, sizeof t2);
    std::memcpy(tau + 24, &t3, sizeof t3);
  }

  const MediumTable& medium_;
  const std::vector<double>* tangent_ = nullptr;
  bool mirror_ = false;
  int n_;
  std::vector<float> u2_, frac_;
  std::vector<double> weight_;
  std::vector<int> node_;
  std::vector<double> w0_, w1_;
};

// The tangent table: per altitude node of the medium (h_i = i dh), the terms
// of the horizontal ray from R + h_i to the top, by the quadrature on
// 2 steps intervals, [node][padded term].  A ray that descends from r along
// mu < 0 to its closest approach l and climbs to the top has the optical
// depth of [l, r] plus this ray's at l, so the table replaces the second of
// its two parts (0.78 of the Earth table's nodes have one, 44 % of the
// samples) by a linear interpolation in altitude.  Measured on every
// descending node of the Earth's table (32 bins) against a 2048-interval
// quadrature, worst error as a fraction of the tolerance max(0.5 % T, 1e-4)
// (and with 1e-5, 1e-6 in place of 1e-4): 0.61 (1.15, 1.28) with both parts
// on 64 intervals; 0.30 (0.68, 0.77) with the table at the medium's 2048
// nodes and 128 intervals; 0.64 (1.15, 1.29) at 64 intervals; 0.77 (1.14,
// 1.36) at 1024 nodes; Catmull-Rom in place of linear interpolation is worse
// (0.55, 2.4, 3.0): the medium's profiles are piecewise linear.
SKYFARM_LUT_SIMD_CLONES
std::vector<double> tangent_table(const MediumTable& medium, int steps) {
  OpticalDepthQuadrature quadrature(medium, 2 * steps);
  const std::size_t K = static_cast<std::size_t>(medium.padded_terms());
  const std::size_t nodes = static_cast<std::size_t>(medium.altitude_samples());
  std::vector<double> table(nodes * K);
  for (std::size_t i = 0; i < nodes; ++i)
    quadrature.terms_to_top(medium.planet_radius_m() + static_cast<double>(i) * medium.altitude_step_m(), 0.0,
                            table.data() + i * K);
  return table;
}

// One row of the table (radius node j): every mu node's transmittance.
SKYFARM_LUT_SIMD_CLONES
void fill_row(OpticalDepthQuadrature& quadrature, std::span<const double> r, std::span<const double> mu,
              int bins, double* terms, double* tau, float* out) {
  const std::size_t B = static_cast<std::size_t>(bins);
  for (std::size_t i = 0; i < mu.size(); ++i) {
    quadrature.terms_to_top(r[i], mu[i], terms);
    quadrature.expand(terms, tau);
    // T in single precision, as stored: e^-tau's relative error (< 1.5e-7) and
    // tau's rounding to float (6e-8 tau) are far below the table's 0.5 %.
    float* T = out + i * B;
    const auto exp_minus = [&](auto bins) __attribute__((always_inline)) {
      for (std::size_t b = 0; b < bins; ++b) T[b] = lut::exp_inline_f(static_cast<float>(-tau[b]));
    };
    if (B == kDefaultBins)
      exp_minus(std::integral_constant<std::size_t, kDefaultBins>{});
    else
      exp_minus(B);
  }
}

// Intervals for the rays of one table row (radius r) that start at r and
// climb: every upward node, and the mirror images of the descending ones.
// Each of them is no thicker than the horizontal ray from r (the path
// length per altitude grows with the zenith angle), whose optical depth
// tau_h(r) the tangent table gives, so its largest bin bounds the rays'
// optical depth, and thin rays need fewer intervals for the same error.
// Measured on the Earth's table (32 bins), per bound, the worst error of
// such rays against a 2048-interval quadrature as a fraction of max(0.5 % T,
// 1e-5): below 1/8, 0.28 at 8 intervals; below 1/4, 0.27 at 16; below 1/2,
// 0.19 at 24; below 1, 0.23 at 32 (0.48 between 1 and 2, so thicker rows
// keep `steps`).
constexpr double kThinRowBound[] = {0.125, 0.25, 0.5, 1.0};
constexpr int kThinRowIntervals[] = {8, 16, 24, 32};
constexpr std::size_t kThinRules = std::size(kThinRowBound);

// The rule for a row whose bound is tau_bound: an index into
// kThinRowIntervals, or kThinRules for `steps` intervals.
std::size_t climb_rule(double tau_bound) {
  std::size_t rule = 0;
  while (rule < kThinRules && !(tau_bound < kThinRowBound[rule])) ++rule;
  return rule;
}

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
  // Every value is written below: resize, not assign (huge_page_allocator.h).
  t.values_.resize(static_cast<std::size_t>(mu_samples) * static_cast<std::size_t>(r_samples) * B);
  const std::vector<double> tangent = tangent_table(medium, t.steps_);
  // One quadrature per rule a row may use (climb_rule), the last on steps.
  std::vector<OpticalDepthQuadrature> quadratures;
  for (std::size_t rule = 0; rule <= kThinRules; ++rule) {
    const int n = rule < kThinRules ? std::min(kThinRowIntervals[rule], t.steps_) : t.steps_;
    quadratures.emplace_back(medium, n);
    quadratures.back().use_tangent_table(&tangent, n < t.steps_);
  }
  std::vector<double> terms(static_cast<std::size_t>(medium.padded_terms())), tau(B);
  std::vector<double> r(static_cast<std::size_t>(mu_samples)), mu(static_cast<std::size_t>(mu_samples));
  for (int j = 0; j < r_samples; ++j) {
    for (std::size_t i = 0; i < mu.size(); ++i)
      t.r_mu_from_unit(static_cast<double>(j) / (r_samples - 1),
                       x_mu_from_v(static_cast<double>(i) / (mu_samples - 1)), &r[i], &mu[i]);
    // The row's bound: the horizontal ray from r, its thickest bin.
    quadratures.back().tangent_terms(r[0], terms.data());
    quadratures.back().expand(terms.data(), tau.data());
    const std::size_t rule = climb_rule(*std::max_element(tau.begin(), tau.end()));
    fill_row(quadratures[rule], r, mu, t.bins_, terms.data(), tau.data(),
             t.values_.data() + static_cast<std::size_t>(j) * mu.size() * B);
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

void TransmittanceLut::optical_depth_to_top(const MediumTable& medium, double r, double mu, int steps, double* tau) {
  OpticalDepthQuadrature quadrature(medium, steps);
  std::vector<double> terms(static_cast<std::size_t>(medium.padded_terms()));
  quadrature.terms_to_top(r, mu, terms.data());
  quadrature.expand(terms.data(), tau);
}

}  // namespace skyfarm
