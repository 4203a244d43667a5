// Colour pipeline: the derived XYZ ↔ linear-sRGB matrices, the sRGB transfer
// function and absolute photometric scaling, each against a published value.
#include "common/spectrum/color.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/data/csv_table.h"
#include "common/spectrum/cie_observer.h"

namespace skyfarm {
namespace {

// IEC 61966-2-1:1999 §5.2 (the published XYZ → linear sRGB matrix, 4 decimals).
TEST(Color, DerivedXyzToSrgbMatrixMatchesIec61966) {
  const Matrix3 published{{{3.2406, -1.5372, -0.4986}, {-0.9689, 1.8758, 0.0415}, {0.0557, -0.2040, 1.0570}}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(kXyzToLinearSrgb[i][j], published[i][j], 1e-3) << "row " << i << " col " << j;
}

// IEC 61966-2-1:1999 §5.2 forward matrix (4 decimals): 0.4124 0.3576 0.1805 /
// 0.2126 0.7152 0.0722 / 0.0193 0.1192 0.9505; the middle row is the BT.709 luma weights.
TEST(Color, DerivedSrgbToXyzMatrixMatchesPublishedAndInverts) {
  const Matrix3 published{{{0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(kLinearSrgbToXyz[i][j], published[i][j], 1e-4) << "row " << i << " col " << j;
      double prod = 0.0;  // (M⁻¹ M)_ij = δ_ij
      for (int k = 0; k < 3; ++k) prod += kXyzToLinearSrgb[i][k] * kLinearSrgbToXyz[k][j];
      EXPECT_NEAR(prod, i == j ? 1.0 : 0.0, 1e-14);
    }
  // RGB = (1, 1, 1) is the D65 white (0.3127, 0.3290) with Y = 1 (construction).
  const Xyz w = linear_srgb_to_xyz({1.0, 1.0, 1.0});
  EXPECT_NEAR(w.y, 1.0, 1e-14);
  EXPECT_NEAR(chromaticity(w).x, 0.3127, 1e-14);
  EXPECT_NEAR(chromaticity(w).y, 0.3290, 1e-14);
}

// XYZ of CIE D65 (data/cie_d65.csv) with the CIE 1931 CMFs on the 1 nm grid.
Xyz d65_xyz() {
  const CsvTable t = CsvTable::embedded("cie_d65.csv");
  const auto& lambda = t.column("wavelength_nm");
  const auto& s = t.column("relative_spd_normalised_100_at_560nm");
  Xyz sum{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    const Xyz c = cie1931_cmf(lambda[i]);
    sum.x += c.x * s[i];
    sum.y += c.y * s[i];
    sum.z += c.z * s[i];
  }
  return sum;
}

// data/README.md §1: "D65 white point from this file plus cie_d65.csv: x = 0.31273, y = 0.32902".
TEST(Color, D65ChromaticityFromTables) {
  const Chromaticity c = chromaticity(d65_xyz());
  EXPECT_NEAR(c.x, 0.31273, 1e-4);
  EXPECT_NEAR(c.y, 0.32902, 1e-4);
}

// sRGB is defined with D65 as its white (IEC 61966-2-1 §4): the tabulated D65
// spectrum maps to R = G = B (±2e-3: the table's chromaticity differs from the
// rounded (0.3127, 0.3290) in the 5th decimal).  pbrt-v4 StdIllumWhitesRGB test.
TEST(Color, D65SpectrumMapsToNeutralSrgb) {
  const Xyz d65 = d65_xyz();
  const Rgb rgb = xyz_to_linear_srgb({d65.x / d65.y, 1.0, d65.z / d65.y});
  EXPECT_NEAR(rgb.r, 1.0, 2e-3);
  EXPECT_NEAR(rgb.g, 1.0, 2e-3);
  EXPECT_NEAR(rgb.b, 1.0, 2e-3);
  EXPECT_NEAR(rgb.r, rgb.g, 2e-3);
  EXPECT_NEAR(rgb.b, rgb.g, 2e-3);
}

// IEC 61966-2-1:1999 §5.2: 12.92 × 0.0031308 = 0.04045 (to 1e-7), and the
// two branches meet at the knee (the standard's constants agree to ~1e-7).
TEST(Color, SrgbTransferIsContinuousAtTheKnee) {
  const double knee = 0.0031308;
  EXPECT_NEAR(srgb_encode(knee), 0.04045, 1e-7);
  const double power_branch = 1.055 * std::pow(knee, 1.0 / 2.4) - 0.055;
  EXPECT_NEAR(srgb_encode(knee), power_branch, 1e-7);
  EXPECT_NEAR(srgb_encode(std::nextafter(knee, 1.0)), srgb_encode(knee), 1e-7);
  EXPECT_NEAR(srgb_decode(0.04045), knee, 1e-8);
  EXPECT_NEAR(srgb_decode(std::nextafter(0.04045, 1.0)), srgb_decode(0.04045), 1e-8);
}

// Known values (IEC 61966-2-1 formulas): 0.5 → 1.055·0.5^(1/2.4) − 0.055 = 0.735357;
// 0 → 0, 1 → 1 (1.055 − 0.055), 0.18 (mid grey) → 0.461356.
TEST(Color, SrgbTransferKnownValues) {
  EXPECT_NEAR(srgb_encode(0.5), 0.7354, 1e-4);
  EXPECT_NEAR(srgb_encode(0.5), 0.735356983, 1e-8);
  EXPECT_DOUBLE_EQ(srgb_encode(0.0), 0.0);
  EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-15);
  EXPECT_NEAR(srgb_encode(0.18), 0.461356, 1e-6);
  EXPECT_NEAR(srgb_decode(0.7354), 0.5, 1e-4);
  EXPECT_NEAR(srgb_decode(1.0), 1.0, 1e-15);
}

TEST(Color, SrgbTransferRoundTrips) {
  for (int i = 0; i <= 1000; ++i) {
    const double l = i / 1000.0;
    EXPECT_NEAR(srgb_decode(srgb_encode(l)), l, 1e-12) << l;
    EXPECT_NEAR(srgb_encode(srgb_decode(l)), l, 1e-12) << l;
  }
  EXPECT_NEAR(srgb_decode(srgb_encode(1e-5)), 1e-5, 1e-18);
}

// SI definition of the candela / CIE 15:2004 §7.1: 1 W m⁻² sr⁻¹ nm⁻¹ over a 1 nm
// band at 555 nm (ȳ = 1) is 683 cd/m².  Over [554.5, 555.5] the interpolated ȳ
// averages 0.99995 (table: ȳ(554) = 0.9997482, ȳ(556) = 0.9998567), hence 682.97.
TEST(Color, MonochromaticBandAt555nmIs683CandelaPerSquareMetre) {
  const PiecewiseLinear band({554.5, 555.5}, {1.0, 1.0}, PiecewiseLinear::Outside::kZero);
  const double y = luminance_cd_m2(band);
  EXPECT_NEAR(y, 683.0, 0.1);
  const double ybar_mean = cie1931_observer().ybar.integral(554.5, 555.5);
  EXPECT_NEAR(y, 683.0 * ybar_mean, 1e-10);

  // The same through the Monte Carlo estimator with the 1 nm range itself.
  std::mt19937_64 rng(555);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double sum = 0.0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    const SampledWavelengths w = sample_wavelengths_uniform((i + U(rng)) / n, 554.5, 555.5);
    sum += spectral_sample_to_xyz(w, {1.0, 1.0, 1.0, 1.0}).y;
  }
  EXPECT_NEAR(sum / n, 683.0 * ybar_mean, 1e-3);
}

// Exactness of spectrum_to_xyz for piecewise-linear spectra: a constant 1
// gives K_m ∫ȳ (CIE 15:2004: equal-energy spectrum, Y = K_m ∫ȳ dλ); an equal-
// energy spectrum has chromaticity (1/3, 1/3) only approximately (the table
// sums differ by 3e-4), which the sums above determine exactly.
TEST(Color, ConstantSpectrumIntegratesToCmfIntegrals) {
  const Xyz c = spectrum_to_xyz(PiecewiseLinear::constant(1.0));
  const CieObserver& o = cie1931_observer();
  EXPECT_NEAR(c.y, 683.0 * cie1931_ybar_integral_nm(), 1e-9);
  EXPECT_NEAR(c.x, 683.0 * o.xbar.integral(360.0, 830.0), 1e-9);
  EXPECT_NEAR(c.z, 683.0 * o.zbar.integral(360.0, 830.0), 1e-9);
  // A ramp (knots off the 1 nm grid): compare with fine midpoint quadrature.
  const PiecewiseLinear ramp({400.25, 700.75}, {0.0, 2.0}, PiecewiseLinear::Outside::kZero);
  double ref = 0.0;
  const int n = 470000;
  for (int i = 0; i < n; ++i) {
    const double l = 360.0 + (i + 0.5) * (470.0 / n);
    ref += cie1931_ybar(l) * ramp(l) * (470.0 / n);
  }
  EXPECT_NEAR(luminance_cd_m2(ramp) / (683.0 * ref), 1.0, 1e-8);
}

// The hero estimator converges to the exact integral: D65 (relative SPD) gives
// the same XYZ by spectral_sample_to_xyz with visible sampling as by
// spectrum_to_xyz (to Monte Carlo error, fixed seed).
TEST(Color, SpectralSampleEstimatorMatchesExactIntegral) {
  const CsvTable t = CsvTable::embedded("cie_d65.csv");
  const PiecewiseLinear d65(t.column("wavelength_nm"), t.column("relative_spd_normalised_100_at_560nm"),
                            PiecewiseLinear::Outside::kZero);
  const Xyz exact = spectrum_to_xyz(d65);
  const VisibleWavelengthSampler sampler(360.0, 830.0);
  std::mt19937_64 rng(65);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Xyz sum{0.0, 0.0, 0.0};
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const SampledWavelengths w = sampler.sample_wavelengths((i + U(rng)) / n);
    std::array<double, kWavelengthsPerPath> L{};
    for (int k = 0; k < kWavelengthsPerPath; ++k) L[k] = d65(w.lambda_nm[k]);
    const Xyz c = spectral_sample_to_xyz(w, L);
    sum.x += c.x;
    sum.y += c.y;
    sum.z += c.z;
  }
  EXPECT_NEAR(sum.x / n / exact.x, 1.0, 1e-3);
  EXPECT_NEAR(sum.y / n / exact.y, 1.0, 1e-3);
  EXPECT_NEAR(sum.z / n / exact.z, 1.0, 1e-3);
}

}  // namespace
}  // namespace skyfarm
