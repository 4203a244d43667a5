// Spectral optical constants of a surface: the complex index of refraction
// n(λ) + i k(λ) (tabulated, or a Sellmeier dispersion formula for glasses and
// water) and the spectral albedo of a diffuse ground.
//
// Parameters
//   wavelengths_nm  where a table is given, nm, finite, > 0, strictly
//                   increasing, at least one point (one point is a constant).
//   n               real part of the index, finite, > 0, one per wavelength.
//   k               extinction coefficient (imaginary part), finite, >= 0,
//                   one per wavelength (0 for a transparent dielectric).
//   albedo          reflectance of a diffuse surface, finite, in [0, 1], one
//                   per wavelength.
//   Sellmeier       n²(λ) − 1 = Σᵢ Bᵢ λ² / (λ² − Cᵢ), λ in µm, Cᵢ in µm²
//                   (Malitson's form with λᵢ is the same with Cᵢ = λᵢ²), with
//                   the wavelength range over which the fit is published.
//   what            the name used in every error message ("gold", a request's
//                   material name).
//
// Evaluation: linear in λ between table points.  Outside the data's range
// (a table's first and last wavelength, a Sellmeier fit's validity range) the
// value is that at the nearest end: clamped, never extrapolated.  Why clamp
// and not throw: the path tracer samples wavelengths over 360-830 nm in its
// inner loop, where an exception would abort a whole render, and two measured
// tables stop inside that range (Bowker's snow starts at 390 nm, Feister and
// Grewe's grounds stop at 800 nm) where their values change slowly.  Why not
// extrapolate: a straight line through measured points leaves the physical
// domain (k < 0, albedo > 1) and a Sellmeier formula has poles.  A caller
// that needs the data to cover a range checks covers() once, up front.
//
// Invalid tables throw std::invalid_argument with a message naming `what`,
// the rule broken and the offending index and value.
#pragma once

#include <complex>
#include <optional>
#include <string_view>
#include <string>
#include <vector>

#include "common/core/piecewise_linear.h"

namespace skyfarm::material {

// n + i k at one wavelength.
struct ComplexIor {
  double n = 1.0;
  double k = 0.0;
  std::complex<double> eta() const { return {n, k}; }
};

// Reflectance at normal incidence from a medium of index 1 (vacuum, and air
// to 3e-4): ((n − 1)² + k²) / ((n + 1)² + k²).
double normal_incidence_reflectance(ComplexIor ior);

// One Sellmeier term Bᵢ λ² / (λ² − Cᵢ).
struct SellmeierTerm {
  double b = 0.0;
  double c_um2 = 0.0;
};

class SellmeierDispersion {
 public:
  // Throws std::invalid_argument (naming `what`) for no terms, non-finite
  // coefficients, a range that is not 0 < min < max, or a range that reaches
  // a pole (λ² = Cᵢ) or a point where n² <= 0.
  SellmeierDispersion(std::vector<SellmeierTerm> terms, double min_wavelength_nm,
                      double max_wavelength_nm, const std::string& what);

  // Reads the data/ coefficient files: a `coefficient,value` header, then
  // rows B1, C1_um2 (or lambda1_um), B2, ..., wavelength_min_um,
  // wavelength_max_um; other rows (temperature_K, nd_1, ...) are ignored.
  // Throws std::runtime_error naming `source` on a malformed file.
  static SellmeierDispersion parse_coefficients(std::string_view csv_text, const std::string& source);

  // n at lambda_nm, clamped to the validity range.
  double n(double lambda_nm) const;

  const std::vector<SellmeierTerm>& terms() const { return terms_; }
  double min_wavelength_nm() const { return min_nm_; }
  double max_wavelength_nm() const { return max_nm_; }

 private:
  double n_unclamped(double lambda_nm) const;

  std::vector<SellmeierTerm> terms_;
  double min_nm_ = 0.0, max_nm_ = 0.0;
};

// n(λ) + i k(λ): n tabulated or from a Sellmeier formula, k tabulated.
class SpectralIor {
 public:
  // n and k tabulated on the same wavelengths.
  static SpectralIor tabulated(const std::vector<double>& wavelengths_nm, const std::vector<double>& n,
                               const std::vector<double>& k, const std::string& what);
  // n from a Sellmeier formula, k tabulated on its own wavelengths.
  static SpectralIor sellmeier(SellmeierDispersion n, const std::vector<double>& k_wavelengths_nm,
                               const std::vector<double>& k, const std::string& what);
  // n from a Sellmeier formula, k = 0 (a transparent glass).
  static SpectralIor sellmeier(SellmeierDispersion n);

  ComplexIor at(double lambda_nm) const { return {n(lambda_nm), k(lambda_nm)}; }
  double n(double lambda_nm) const;
  double k(double lambda_nm) const { return k_(lambda_nm); }

  // Whether both n and k have data over [lo_nm, hi_nm] (no clamping there).
  bool covers(double lo_nm, double hi_nm) const;

  bool has_sellmeier() const { return sellmeier_.has_value(); }

 private:
  SpectralIor() = default;

  std::optional<SellmeierDispersion> sellmeier_;  // n from the formula when set
  PiecewiseLinear n_table_;                        // else n from the table
  PiecewiseLinear k_;
};

// The spectral albedo of a diffuse surface, in [0, 1].
class SpectralAlbedo {
 public:
  SpectralAlbedo(const std::vector<double>& wavelengths_nm, const std::vector<double>& albedo,
                 const std::string& what);

  double at(double lambda_nm) const { return table_(lambda_nm); }
  bool covers(double lo_nm, double hi_nm) const;
  // The table itself, for the ground (LambertianGround takes a PiecewiseLinear).
  const PiecewiseLinear& table() const { return table_; }

 private:
  PiecewiseLinear table_;
};

}  // namespace skyfarm::material
