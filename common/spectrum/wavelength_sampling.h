// Wavelength sampling for spectral transport: several wavelengths per path
// (hero-wavelength sampling), stratified inside the requested wavelength range
// or batch.
//
// The estimator.  A spectral quantity's integral over [min, max], e.g. a
// tristimulus value X = ∫ x̄(λ) L(λ) dλ, is estimated from one path's
// wavelengths by
//
//     I ≈ (1/N) Σ_i f(λ_i) / p(λ_i),        N = kWavelengthsPerPath,
//
// where p(λ_i) is the marginal density (per nm) of λ_i alone.  Every λ_i is
// marginally distributed with p (the rotated u_i are each uniform on [0, 1)),
// so every term is unbiased on its own and so is their mean; the rotation only
// makes the four terms negatively correlated (stratified), which lowers the
// variance.  Wilkie, Nawaz, Droske, Weidlich, Hanika (2014), "Hero Wavelength
// Spectral Sampling", EGSR; pbrt-v4 SampledWavelengths::SampleVisible and
// SampledSpectrum::ToXYZ.
//
// Batches.  The farm splits [min, max] into B equal batches; a
// unit of work samples its wavelengths over its batch [batch_edge(b),
// batch_edge(b + 1)] only, with the batch's own pdf.  Since ∫_min^max f =
// Σ_b ∫_batch_b f, the full-spectrum estimate is the SUM over batches of the
// per-batch estimates (sums are merged, never averaged).
#pragma once
#include <array>

namespace skyfarm {

inline constexpr int kWavelengthsPerPath = 4;

// Default spectral range of a render, nm (the CIE 1931 table).
inline constexpr double kDefaultMinWavelength_nm = 360.0;
inline constexpr double kDefaultMaxWavelength_nm = 830.0;

// The wavelengths carried by one path.  lambda_nm[0] is the hero wavelength
// (the one that drives distance sampling); pdf[i] is the density per nm of
// lambda_nm[i]'s own marginal distribution.
struct SampledWavelengths {
  std::array<double, kWavelengthsPerPath> lambda_nm;
  std::array<double, kWavelengthsPerPath> pdf;
};

// ---------------------------------------------------------------------------
// Stratified rotations of one uniform number.
//
// u_i = (u + i/N) mod 1, i = 0..N−1 (Wilkie et al. 2014, §3; pbrt-v4
// SampledWavelengths::SampleVisible).  Computed as u_i = ((j + i) mod N + f)/N
// with j = ⌊N u⌋, f = N u − j (both exact in binary floating point) and
// clamped below (k + 1)/N, so that rounding can never move two u_i into the
// same stratum: u_i lies in [k/N, (k+1)/N) with k = (j + i) mod N, i.e. the
// four values occupy the four quarters of [0, 1) exactly once.  u_0 = u.
// u must be in [0, 1) (values outside are clamped into it).
std::array<double, kWavelengthsPerPath> rotated_strata(double u);

// ---------------------------------------------------------------------------
// Uniform sampling on [min_nm, max_nm] (min_nm < max_nm, both finite; throws
// std::invalid_argument otherwise).
//
// p(λ) = 1 / (max − min) on [min, max], 0 outside;  λ(u) = min + u (max − min).
double sample_uniform_wavelength(double u, double min_nm, double max_nm);
double uniform_wavelength_pdf(double lambda_nm, double min_nm, double max_nm);
// Four stratified wavelengths λ_i = λ(u_i) with u_i = rotated_strata(u).
SampledWavelengths sample_wavelengths_uniform(double u, double min_nm, double max_nm);

// ---------------------------------------------------------------------------
// "Visible" importance sampling: the sech² density of pbrt-v4
// (util/sampling.h, VisibleWavelengthsPDF / SampleVisibleWavelengths) and
// Mitsuba 3 (core/spectrum.h, pdf_rgb_spectrum / sample_rgb_spectrum), which
// roughly follows the sum of the CIE matching functions, here restricted and
// renormalised to any [min, max]:
//
//     p(λ) = a sech²(a (λ − λc)) / (tanh(a (max − λc)) − tanh(a (min − λc))),
//     a = 0.0072 nm⁻¹, λc = 538 nm;
//     F(λ) = (tanh(a (λ − λc)) − tanh(a (min − λc))) / (same denominator).
//
// On [360, 830] this is pbrt's 0.0039398042 / cosh²(0.0072 (λ − 538)).  The
// implementation inverts F exactly (atanh, written as a logit) in a form with
// no cancellation, so ranges far from 538 nm (280–320 nm, 800–830 nm, the IR)
// and ranges as narrow as 1 nm keep full double precision; see the .cpp.
class VisibleWavelengthSampler {
 public:
  static constexpr double kA_per_nm = 0.0072;      // a
  static constexpr double kLambdaC_nm = 538.0;     // λc

  // min_nm < max_nm, both finite; throws std::invalid_argument otherwise.
  VisibleWavelengthSampler(double min_nm, double max_nm);

  double min_nm() const { return min_nm_; }
  double max_nm() const { return max_nm_; }
  // λ = F⁻¹(u), u ∈ [0, 1); the result is in [min, max].
  double sample(double u) const;
  // p(λ) per nm; 0 outside [min, max].
  double pdf(double lambda_nm) const;
  // Four stratified wavelengths λ_i = F⁻¹(u_i), u_i = rotated_strata(u).
  SampledWavelengths sample_wavelengths(double u) const;

 private:
  enum class Side { kBelow, kStraddle, kAbove };  // the range relative to λc
  double min_nm_, max_nm_;
  double x0_, x1_;        // a (min − λc), a (max − λc)
  Side side_;
  // kStraddle: σ(2 x0), σ(−2 x1) and D = (tanh x1 − tanh x0) / 2.
  double sigma0_ = 0.0, sigma1c_ = 0.0, D_ = 0.0;
  // kBelow / kAbove, in the mirrored frame where the range is [y0, y1] ≤ 0:
  // log σ(2 y1), r0 = σ(2 y0) / σ(2 y1) and 1 − r0.
  double log_sigma1_ = 0.0, r0_ = 0.0, one_minus_r0_ = 0.0;
  // log of the normalisation: log a + log cosh x0 + log cosh x1 − log sinh(x1 − x0).
  double log_norm_ = 0.0;
};

// Single-wavelength and hero-wavelength convenience forms (they build the
// sampler each call; keep a VisibleWavelengthSampler in hot loops).
double sample_visible_wavelength(double u, double min_nm, double max_nm);
double visible_wavelength_pdf(double lambda_nm, double min_nm, double max_nm);
SampledWavelengths sample_wavelengths_visible(double u, double min_nm, double max_nm);

// ---------------------------------------------------------------------------
// Batches: [min, max] cut into B equal sub-ranges, batch b = 0..B−1 covering
// [batch_edge_nm(b), batch_edge_nm(b + 1)].
//
// edge_k = min + (max − min) k / B, with edge_0 = min and edge_B = max exactly;
// neighbouring batches share the same edge value bit for bit.
struct WavelengthRange {
  double min_nm;
  double max_nm;
};
// Throws std::invalid_argument unless min < max (finite), B ≥ 1, 0 ≤ k ≤ B.
double batch_edge_nm(double min_nm, double max_nm, int k, int batches);
WavelengthRange batch_range(double min_nm, double max_nm, int b, int batches);

// u ∈ [0, 1) mapped uniformly into batch b of B of [min, max]:
// λ = edge_b + u (edge_{b+1} − edge_b); its pdf is uniform_wavelength_pdf over
// batch_range(b) = B / (max − min).  For importance sampling inside a batch use
// VisibleWavelengthSampler(batch_range(...)) instead.
double stratified_in_batch(double u, double min_nm, double max_nm, int b, int batches);

}  // namespace skyfarm
