// Colour: spectral radiance → CIE 1931 XYZ (absolute, Y in cd/m²) → linear
// Rec.709/sRGB (D65) → sRGB-encoded values.
//
// Convention.  X, Y, Z = K_m ∫ (x̄, ȳ, z̄)(λ) L(λ) dλ with L the spectral
// radiance in W m⁻² sr⁻¹ nm⁻¹ and K_m = 683 lm/W (kMaxLuminousEfficacy): Y is
// the luminance in cd/m², and X, Z carry the same scale.  The EXR stores these
// absolute values; linear sRGB values are obtained from them by a matrix, so
// they are in the same absolute units (R = G = B = Y for a D65-white spectrum).
#pragma once
#include <array>

#include "common/core/piecewise_linear.h"
#include "common/spectrum/wavelength_sampling.h"

namespace skyfarm {

struct Xyz {
  double x, y, z;
};
struct Rgb {
  double r, g, b;
};
// CIE 1931 chromaticity coordinates (x, y).
struct Chromaticity {
  double x, y;
};

// Row-major 3×3 matrix: m[row][col]; applied as out_row = Σ_col m[row][col] in_col.
using Matrix3 = std::array<std::array<double, 3>, 3>;

constexpr std::array<double, 3> mat3_mul(const Matrix3& m, const std::array<double, 3>& v) {
  return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
          m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
          m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

// Inverse by the adjugate: M⁻¹ = adj(M) / det(M) (det ≠ 0 assumed; the colour
// matrices here are well conditioned).
constexpr Matrix3 mat3_inverse(const Matrix3& m) {
  const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
  const double s = 1.0 / det;
  return {{{c00 * s, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * s, (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * s},
           {c01 * s, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * s, (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * s},
           {c02 * s, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * s, (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * s}}};
}

// XYZ of a colour of chromaticity (x, y) and luminance Y = 1: (x/y, 1, (1 − x − y)/y).
constexpr std::array<double, 3> xyz_of_chromaticity(Chromaticity c) {
  return {c.x / c.y, 1.0, (1.0 - c.x - c.y) / c.y};
}

// RGB → XYZ matrix of an additive colour space from its primaries and white
// point (SMPTE RP 177-1993 §3.3; Poynton, "Digital Video and HD", 2nd ed.,
// ch. 26): with P = [XYZ(r) XYZ(g) XYZ(b)] (columns, each of Y = 1) and W the
// white's XYZ with Y = 1, solve S = P⁻¹ W for the primaries' scales so that
// RGB = (1, 1, 1) maps to the white; then M = P diag(S).
constexpr Matrix3 rgb_to_xyz_matrix(Chromaticity r, Chromaticity g, Chromaticity b, Chromaticity white) {
  const auto cr = xyz_of_chromaticity(r), cg = xyz_of_chromaticity(g), cb = xyz_of_chromaticity(b);
  const Matrix3 P{{{cr[0], cg[0], cb[0]}, {cr[1], cg[1], cb[1]}, {cr[2], cg[2], cb[2]}}};
  const auto S = mat3_mul(mat3_inverse(P), xyz_of_chromaticity(white));
  Matrix3 M{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M[i][j] = P[i][j] * S[j];
  return M;
}

// ITU-R BT.709-6 primaries and the D65 white point (= IEC 61966-2-1 sRGB).
inline constexpr Chromaticity kRec709Red{0.64, 0.33};
inline constexpr Chromaticity kRec709Green{0.30, 0.60};
inline constexpr Chromaticity kRec709Blue{0.15, 0.06};
inline constexpr Chromaticity kD65White{0.3127, 0.3290};

// Linear Rec.709/sRGB (D65) → XYZ, derived from the primaries above, and its inverse.
inline constexpr Matrix3 kLinearSrgbToXyz =
    rgb_to_xyz_matrix(kRec709Red, kRec709Green, kRec709Blue, kD65White);
inline constexpr Matrix3 kXyzToLinearSrgb = mat3_inverse(kLinearSrgbToXyz);

constexpr Rgb xyz_to_linear_srgb(const Xyz& c) {
  const auto v = mat3_mul(kXyzToLinearSrgb, {c.x, c.y, c.z});
  return {v[0], v[1], v[2]};
}
constexpr Xyz linear_srgb_to_xyz(const Rgb& c) {
  const auto v = mat3_mul(kLinearSrgbToXyz, {c.r, c.g, c.b});
  return {v[0], v[1], v[2]};
}

// Chromaticity x = X/(X+Y+Z), y = Y/(X+Y+Z) (CIE 15:2004 §7.3).
Chromaticity chromaticity(const Xyz& c);

// sRGB transfer function (IEC 61966-2-1:1999 §5.2, the "gamma" encoding):
//   V = 12.92 L                 for L ≤ 0.0031308,
//   V = 1.055 L^(1/2.4) − 0.055 otherwise;
// and its inverse (§5.2, decoding):
//   L = V / 12.92               for V ≤ 0.04045,
//   L = ((V + 0.055)/1.055)^2.4 otherwise.
// Negative inputs follow the linear segment; no clamping (the PNG writer
// clamps to [0, 1]).  The two published thresholds are consistent to ~1e-8
// (12.92 × 0.0031308 = 0.0404499), so the round trip is exact to that level.
double srgb_encode(double linear);
double srgb_decode(double encoded);

// Absolute XYZ of one path's spectral sample (pbrt-v4 SampledSpectrum::ToXYZ,
// but absolute instead of divided by ∫ȳ):
//   (X, Y, Z) = K_m · (1/N) Σ_i (x̄, ȳ, z̄)(λ_i) L_i / p(λ_i),   K_m = 683 lm/W,
// the hero-wavelength estimator of wavelength_sampling.h with L_i in
// W m⁻² sr⁻¹ nm⁻¹.  A wavelength with pdf 0 contributes nothing.
Xyz spectral_sample_to_xyz(const SampledWavelengths& lambda, const std::array<double, kWavelengthsPerPath>& L);

// Absolute XYZ of a tabulated spectral radiance L (W m⁻² sr⁻¹ nm⁻¹), linear
// between its knots as PiecewiseLinear evaluates it (zero or clamped outside
// as the table says):
//   (X, Y, Z) = K_m ∫_{360}^{830} (x̄, ȳ, z̄)(λ) L(λ) dλ.
// Both factors are linear between the merged knots, so Simpson's rule on each
// sub-interval integrates their product exactly.
Xyz spectrum_to_xyz(const PiecewiseLinear& L);

// Luminance in cd/m²: Y = K_m ∫ ȳ(λ) L(λ) dλ (CIE 15:2004 §7.1; K_m = 683 lm/W).
double luminance_cd_m2(const PiecewiseLinear& L);

}  // namespace skyfarm
