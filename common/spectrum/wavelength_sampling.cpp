#include "common/spectrum/wavelength_sampling.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace skyfarm {
namespace {

constexpr double kLn2 = 0.69314718055994530942;

void check_range(double min_nm, double max_nm, const char* who) {
  if (!std::isfinite(min_nm) || !std::isfinite(max_nm) || !(min_nm < max_nm))
    throw std::invalid_argument(std::string(who) + ": wavelength range [" + std::to_string(min_nm) +
                                ", " + std::to_string(max_nm) + "] nm must be finite with min < max");
}

// The largest double below a positive finite x: std::nextafter(x, 0.0)
// (one step down in the bit pattern), but constexpr: nextafter is a library
// call, and rotated_strata ran five per path.
constexpr double double_below(double x) { return std::bit_cast<double>(std::bit_cast<std::uint64_t>(x) - 1); }

// u clamped into [0, 1) (the largest double below 1 is 1 − 2⁻⁵³); NaN → 0.
double clamp_unit(double u) {
  if (!(u > 0.0)) return 0.0;
  return std::min(u, double_below(1.0));
}

// log cosh x = |x| + log(1 + e^{−2|x|}) − log 2, without overflow for any x.
double log_cosh(double x) {
  const double ax = std::abs(x);
  return ax + std::log1p(std::exp(-2.0 * ax)) - kLn2;
}

// log sinh Δ = Δ + log(1 − e^{−2Δ}) − log 2 for Δ > 0, accurate for Δ → 0
// (expm1) and without overflow for large Δ.
double log_sinh(double delta) { return delta + std::log(-std::expm1(-2.0 * delta)) - kLn2; }

// log σ(2y) for y ≤ 0, σ(z) = 1 / (1 + e^{−z}) the logistic function:
// log σ(2y) = 2y − log(1 + e^{2y}) (e^{2y} ≤ 1: no overflow, no cancellation).
double log_sigma_2y_nonpositive(double y) { return 2.0 * y - std::log1p(std::exp(2.0 * y)); }

// σ(z) = 1 / (1 + e^{−z}); → 0 (not NaN) when e^{−z} overflows.
double sigma(double z) { return 1.0 / (1.0 + std::exp(-z)); }

}  // namespace

// ---------------------------------------------------------------------------
// Rotations: u_i = (u + i/N) mod 1 (Wilkie et al. 2014; pbrt-v4
// SampledWavelengths::SampleVisible), computed stratum by stratum.
std::array<double, kWavelengthsPerPath> rotated_strata(double u) {
  constexpr double n = kWavelengthsPerPath;
  // The largest double below each stratum's top (k + 1)/N.
  constexpr std::array<double, kWavelengthsPerPath> stratum_tops = [] {
    std::array<double, kWavelengthsPerPath> tops{};
    for (int k = 0; k < kWavelengthsPerPath; ++k) tops[static_cast<std::size_t>(k)] = double_below((k + 1) / n);
    return tops;
  }();
  const double s = clamp_unit(u) * n;                  // exact: N is a power of two
  const int j = std::min(static_cast<int>(s), kWavelengthsPerPath - 1);
  const double f = s - j;                              // exact (Sterbenz), f ∈ [0, 1)
  std::array<double, kWavelengthsPerPath> ui{};
  for (int i = 0; i < kWavelengthsPerPath; ++i) {
    const int k = (j + i) % kWavelengthsPerPath;
    // k + f may round up to k + 1 when f is within an ulp of 1: keep u_i in
    // its stratum [k/N, (k+1)/N).
    ui[static_cast<std::size_t>(i)] = std::min((k + f) / n, stratum_tops[static_cast<std::size_t>(k)]);
  }
  return ui;
}

// ---------------------------------------------------------------------------
// Uniform: p(λ) = 1/(max − min), λ(u) = min + u (max − min).
double sample_uniform_wavelength(double u, double min_nm, double max_nm) {
  check_range(min_nm, max_nm, "sample_uniform_wavelength");
  return std::clamp(min_nm + clamp_unit(u) * (max_nm - min_nm), min_nm, max_nm);
}

double uniform_wavelength_pdf(double lambda_nm, double min_nm, double max_nm) {
  check_range(min_nm, max_nm, "uniform_wavelength_pdf");
  return (lambda_nm >= min_nm && lambda_nm <= max_nm) ? 1.0 / (max_nm - min_nm) : 0.0;
}

SampledWavelengths sample_wavelengths_uniform(double u, double min_nm, double max_nm) {
  check_range(min_nm, max_nm, "sample_wavelengths_uniform");
  SampledWavelengths w{};
  const auto ui = rotated_strata(u);
  const double p = 1.0 / (max_nm - min_nm);
  for (std::size_t i = 0; i < ui.size(); ++i) {
    w.lambda_nm[i] = std::clamp(min_nm + ui[i] * (max_nm - min_nm), min_nm, max_nm);
    w.pdf[i] = p;
  }
  return w;
}

// ---------------------------------------------------------------------------
// Visible (sech²) sampling.  With x = a (λ − λc), x0 = a (min − λc),
// x1 = a (max − λc), the density in x is ∝ sech² x and the CDF is
//
//   F = (tanh x − tanh x0) / (tanh x1 − tanh x0) = (σ(2x) − σ(2x0)) / (σ(2x1) − σ(2x0)),
//
// because tanh x = 2 σ(2x) − 1 with σ the logistic function (the sech²
// density is a logistic distribution of scale 1/(2a)).  Inverting the tanh
// form directly, λ = λc + atanh(tanh x0 + u (tanh x1 − tanh x0)) / a, loses
// digits when both tanh are close to ±1 (a range far from 538 nm: the
// difference cancels and atanh is ill-conditioned near ±1).  Three cases:
//
// * Range straddling λc (x0 < 0 < x1): the logit form x = ½ log(p/q) with
//     p = σ(2x) = σ(2x0) + u D,   q = 1 − σ(2x) = σ(−2x1) + (1 − u) D,
//     D = (tanh x1 − tanh x0)/2 (the two tanh have opposite signs),
//   sums of non-negative terms only.
// * Range below λc (x1 ≤ 0): with r(x) = σ(2x)/σ(2x1) ∈ (0, 1],
//     F = (r − r0)/(1 − r0),  r0 = r(x0) = exp(log σ(2x0) − log σ(2x1)),
//   1 − r0 = −expm1(·); invert r = r0 + u (1 − r0), then
//     2x = logit(r σ(2x1)) = log r + log σ(2x1) − log(1 − r σ(2x1)),
//   with r σ(2x1) ≤ ½, every term in logs (no underflow, no cancellation).
// * Range above λc (x0 ≥ 0): mirror, y = −x ∈ [−x1, −x0], CDF 1 − u.
//
// The pdf uses tanh x1 − tanh x0 = sinh(x1 − x0)/(cosh x0 cosh x1), in logs:
//   log p = log a + log cosh x0 + log cosh x1 − log sinh(a (max − min)) − 2 log cosh x.
VisibleWavelengthSampler::VisibleWavelengthSampler(double min_nm, double max_nm)
    : min_nm_(min_nm), max_nm_(max_nm) {
  check_range(min_nm, max_nm, "VisibleWavelengthSampler");
  x0_ = kA_per_nm * (min_nm - kLambdaC_nm);
  x1_ = kA_per_nm * (max_nm - kLambdaC_nm);
  const double delta = kA_per_nm * (max_nm - min_nm);  // x1 − x0 without cancellation
  log_norm_ = std::log(kA_per_nm) + log_cosh(x0_) + log_cosh(x1_) - log_sinh(delta);

  if (x0_ < 0.0 && x1_ > 0.0) {
    side_ = Side::kStraddle;
    sigma0_ = sigma(2.0 * x0_);
    sigma1c_ = sigma(-2.0 * x1_);
    D_ = 0.5 * (std::tanh(x1_) - std::tanh(x0_));
    return;
  }
  side_ = (x1_ <= 0.0) ? Side::kBelow : Side::kAbove;
  // Mirrored frame [y0, y1], y1 ≤ 0.
  const double y0 = (side_ == Side::kBelow) ? x0_ : -x1_;
  const double y1 = (side_ == Side::kBelow) ? x1_ : -x0_;
  log_sigma1_ = log_sigma_2y_nonpositive(y1);
  // log r0 = log σ(2y0) − log σ(2y1) = −2Δ − log1p(e^{2y0}) + log1p(e^{2y1}).
  const double log_r0 = -2.0 * delta - std::log1p(std::exp(2.0 * y0)) + std::log1p(std::exp(2.0 * y1));
  r0_ = std::exp(log_r0);
  one_minus_r0_ = -std::expm1(log_r0);
}

double VisibleWavelengthSampler::sample(double u) const {
  u = clamp_unit(u);
  double x;
  if (side_ == Side::kStraddle) {
    const double p = sigma0_ + u * D_;
    const double q = sigma1c_ + (1.0 - u) * D_;
    x = 0.5 * (std::log(p) - std::log(q));  // ±∞ only at an underflowed end: clamped below
  } else {
    // CDF value in the mirrored frame.
    const double v = (side_ == Side::kBelow) ? u : 1.0 - u;
    const double r = r0_ + v * one_minus_r0_;
    const double log_rs = std::log(r) + log_sigma1_;  // log(r σ(2y1)), ≤ log ½
    const double y = 0.5 * (log_rs - std::log1p(-std::exp(log_rs)));
    x = (side_ == Side::kBelow) ? y : -y;
  }
  const double lambda = kLambdaC_nm + x / kA_per_nm;
  return std::isnan(lambda) ? min_nm_ : std::clamp(lambda, min_nm_, max_nm_);
}

double VisibleWavelengthSampler::pdf(double lambda_nm) const {
  if (!(lambda_nm >= min_nm_ && lambda_nm <= max_nm_)) return 0.0;
  const double x = kA_per_nm * (lambda_nm - kLambdaC_nm);
  return std::exp(log_norm_ - 2.0 * log_cosh(x));
}

SampledWavelengths VisibleWavelengthSampler::sample_wavelengths(double u) const {
  SampledWavelengths w{};
  const auto ui = rotated_strata(u);
  for (std::size_t i = 0; i < ui.size(); ++i) {
    w.lambda_nm[i] = sample(ui[i]);
    w.pdf[i] = pdf(w.lambda_nm[i]);
  }
  return w;
}

double sample_visible_wavelength(double u, double min_nm, double max_nm) {
  return VisibleWavelengthSampler(min_nm, max_nm).sample(u);
}

double visible_wavelength_pdf(double lambda_nm, double min_nm, double max_nm) {
  return VisibleWavelengthSampler(min_nm, max_nm).pdf(lambda_nm);
}

SampledWavelengths sample_wavelengths_visible(double u, double min_nm, double max_nm) {
  return VisibleWavelengthSampler(min_nm, max_nm).sample_wavelengths(u);
}

// ---------------------------------------------------------------------------
// Batches: edge_k = min + (max − min) k / B, edge_0 = min, edge_B = max.
double batch_edge_nm(double min_nm, double max_nm, int k, int batches) {
  check_range(min_nm, max_nm, "batch_edge_nm");
  if (batches < 1 || k < 0 || k > batches)
    throw std::invalid_argument("batch_edge_nm: edge " + std::to_string(k) + " of " +
                                std::to_string(batches) + " batches is out of range");
  if (k == 0) return min_nm;
  if (k == batches) return max_nm;
  return std::min(min_nm + (max_nm - min_nm) * k / batches, max_nm);
}

WavelengthRange batch_range(double min_nm, double max_nm, int b, int batches) {
  if (b < 0 || b >= batches)
    throw std::invalid_argument("batch_range: batch " + std::to_string(b) + " of " +
                                std::to_string(batches) + " is out of range");
  return {batch_edge_nm(min_nm, max_nm, b, batches), batch_edge_nm(min_nm, max_nm, b + 1, batches)};
}

double stratified_in_batch(double u, double min_nm, double max_nm, int b, int batches) {
  const WavelengthRange r = batch_range(min_nm, max_nm, b, batches);
  return std::clamp(r.min_nm + clamp_unit(u) * (r.max_nm - r.min_nm), r.min_nm, r.max_nm);
}

}  // namespace skyfarm
