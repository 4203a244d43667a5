// The image-level error estimate: luminance-weighted and per linear sRGB
// channel relative RMS, e = sqrt(sum var / sum mean^2), against hand-computed
// values; excluded (sun) pixels and pixels without an estimate are left out.
#include "common/film/error_estimate.h"

#include <gtest/gtest.h>

#include <cmath>

namespace skyfarm {
namespace {

// Pixel (0,0): R = 1, 3; G = 2, 2; B = 4, 4  ->  means 2, 2, 4; var of mean 1, 0, 0.
// Pixel (1,0): R = 6, 6; G = 1, 5; B = 2, 2  ->  means 6, 3, 2; var of mean 0, 4, 0.
FilmTile two_pixel_tile() {
  FilmTile t(0, 0, 3, 1, 1);
  auto add = [&](int x, double r, double g, double b) { t.add_sample(x, 0, 0, linear_srgb_to_xyz(Rgb{r, g, b}), 0.0); };
  add(0, 1, 2, 4);
  add(0, 3, 2, 4);
  add(1, 6, 1, 2);
  add(1, 6, 5, 2);
  add(2, 1, 1, 1);  // one sample: no estimate
  return t;
}

TEST(ErrorEstimate, PerChannelRelativeRmsIsHandComputed) {
  const ErrorSums s = error_sums(two_pixel_tile());
  EXPECT_EQ(s.unknown, 1);
  const auto rgb = s.relative_rms_rgb();
  ASSERT_TRUE(rgb.has_value());
  EXPECT_NEAR(rgb->r, std::sqrt(1.0 / (4.0 + 36.0)), 1e-12);
  EXPECT_NEAR(rgb->g, std::sqrt(4.0 / (4.0 + 9.0)), 1e-12);
  EXPECT_NEAR(rgb->b, 0.0, 1e-7);
  // The luminance estimate is the same formula on Y = wR R + wG G + wB B.
  const double wR = linear_srgb_to_xyz(Rgb{1, 0, 0}).y, wG = linear_srgb_to_xyz(Rgb{0, 1, 0}).y,
               wB = linear_srgb_to_xyz(Rgb{0, 0, 1}).y;
  const double Y0 = wR * 2 + wG * 2 + wB * 4, Y1 = wR * 6 + wG * 3 + wB * 2;
  const double var0 = wR * wR * 1.0, var1 = wG * wG * 4.0;
  ASSERT_TRUE(s.relative_rms().has_value());
  EXPECT_NEAR(*s.relative_rms(), std::sqrt((var0 + var1) / (Y0 * Y0 + Y1 * Y1)), 1e-9);
}

TEST(ErrorEstimate, ExcludedPixelsAndSumsThatAdd) {
  const FilmTile t = two_pixel_tile();
  const ErrorSums without_first = error_sums(t, {0u}, 3);
  const auto rgb = without_first.relative_rms_rgb();
  ASSERT_TRUE(rgb.has_value());
  EXPECT_NEAR(rgb->r, 0.0, 1e-7);
  EXPECT_NEAR(rgb->g, std::sqrt(4.0 / 9.0), 1e-12);
  // Sums of parts add to the sums of the whole.
  ErrorSums a = error_sums(t, {1u, 2u}, 3), b = error_sums(t, {0u}, 3);
  a.add(b);
  const ErrorSums whole = error_sums(t);
  EXPECT_NEAR(a.sum_var_rgb.g, whole.sum_var_rgb.g, 1e-12);
  EXPECT_NEAR(a.sum_rgb2.r, whole.sum_rgb2.r, 1e-12);
  EXPECT_EQ(a.unknown, whole.unknown);
}

TEST(ErrorEstimate, NothingKnownIsNulloptNotZero) {
  FilmTile t(0, 0, 2, 1, 1);
  t.add_sample(0, 0, 0, Xyz{1, 1, 1}, 0.0);
  const ErrorSums s = error_sums(t);
  EXPECT_FALSE(s.relative_rms().has_value());
  EXPECT_FALSE(s.relative_rms_rgb().has_value());
  EXPECT_EQ(s.unknown, 1);
}

}  // namespace
}  // namespace skyfarm
