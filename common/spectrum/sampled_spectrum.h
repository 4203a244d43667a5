// Values of a spectral quantity at the path's kWavelengthsPerPath wavelengths
// (pbrt-v4's SampledSpectrum): radiance, throughput, coefficients, and the
// rescaled path pdfs of spectral MIS.  Arithmetic is element-wise.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

#include "common/spectrum/wavelength_sampling.h"

namespace skyfarm {

struct SampledSpectrum {
  std::array<double, kWavelengthsPerPath> v{};

  SampledSpectrum() = default;
  explicit SampledSpectrum(double c) { v.fill(c); }

  double& operator[](int i) { return v[static_cast<std::size_t>(i)]; }
  double operator[](int i) const { return v[static_cast<std::size_t>(i)]; }

  double average() const {
    double s = 0.0;
    for (double x : v) s += x;
    return s / kWavelengthsPerPath;
  }
  double max() const { return *std::max_element(v.begin(), v.end()); }
  bool is_zero() const {
    for (double x : v)
      if (x != 0.0) return false;
    return true;
  }
  bool is_finite() const {
    for (double x : v)
      if (!std::isfinite(x)) return false;
    return true;
  }

#define SKYFARM_SPECTRUM_OP(op)                                                    \
  SampledSpectrum& operator op##=(const SampledSpectrum& o) {                      \
    for (std::size_t i = 0; i < v.size(); ++i) v[i] op##= o.v[i];                 \
    return *this;                                                                  \
  }                                                                                \
  SampledSpectrum& operator op##=(double s) {                                      \
    for (double& x : v) x op##= s;                                                \
    return *this;                                                                  \
  }                                                                                \
  friend SampledSpectrum operator op(SampledSpectrum a, const SampledSpectrum& b) { \
    return a op##= b;                                                             \
  }                                                                                \
  friend SampledSpectrum operator op(SampledSpectrum a, double s) { return a op##= s; }
  SKYFARM_SPECTRUM_OP(+)
  SKYFARM_SPECTRUM_OP(-)
  SKYFARM_SPECTRUM_OP(*)
#undef SKYFARM_SPECTRUM_OP

  friend SampledSpectrum operator*(double s, SampledSpectrum a) { return a *= s; }
  // Division with 0/0 := 0 (a zero pdf means "never sampled this way").
  friend SampledSpectrum safe_div(const SampledSpectrum& a, const SampledSpectrum& b) {
    SampledSpectrum r;
    for (std::size_t i = 0; i < r.v.size(); ++i) r.v[i] = b.v[i] != 0.0 ? a.v[i] / b.v[i] : 0.0;
    return r;
  }
  friend SampledSpectrum exp_neg(const SampledSpectrum& a) {
    SampledSpectrum r;
    for (std::size_t i = 0; i < r.v.size(); ++i) r.v[i] = std::exp(-a.v[i]);
    return r;
  }
  // max(0, a) per wavelength (null-collision coefficients against round-off).
  friend SampledSpectrum clamp_zero(const SampledSpectrum& a) {
    SampledSpectrum r;
    for (std::size_t i = 0; i < r.v.size(); ++i) r.v[i] = std::max(0.0, a.v[i]);
    return r;
  }
};

}  // namespace skyfarm
