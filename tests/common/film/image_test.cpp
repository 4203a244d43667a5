// Image: absolute linear Rec.709 from the mean XYZ (a D65 white of luminance
// Y gives R = G = B = Y), spectral band means, the relative-error layer with
// its explicit "unknown", and resolve() of tiles into their place.
#include "common/film/image.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/spectrum/wavelength_sampling.h"

namespace skyfarm {
namespace {

Xyz d65_white(double luminance) {
  const auto w = xyz_of_chromaticity(kD65White);
  return {w[0] * luminance, w[1] * luminance, w[2] * luminance};
}

TEST(Image, D65WhiteMapsToEqualRgbInCandelasPerSquareMetre) {
  Image img(2, 1);
  img.set_xyz(0, 0, d65_white(4000.0));
  img.set_xyz(1, 0, d65_white(1.0));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(img.rgb(0, 0)[c], 4000.0f, 4000.0f * 1e-6f);
    EXPECT_NEAR(img.rgb(1, 0)[c], 1.0f, 1e-6f);
  }
  EXPECT_NEAR(img.luminance(0, 0), 4000.0, 4000.0 * 1e-6);
}

TEST(Image, StoresFloatsOnlyAndStartsBlack) {
  Image img(8, 4, {SpectralLayout{360, 830, 4}, true});
  EXPECT_EQ(img.rgb().size(), 8u * 4u * 3u);
  EXPECT_EQ(sizeof(img.rgb()[0]), sizeof(float));
  EXPECT_EQ(img.relative_error().size(), 8u * 4u);
  EXPECT_EQ(img.rgb(7, 3)[1], 0.0f);
  EXPECT_FALSE(img.relative_error(7, 3).has_value());  // unknown until resolved
  EXPECT_TRUE(img.metadata().count(metadata_key::kSoftwareVersion));
  EXPECT_THROW(Image(0, 4), std::invalid_argument);
  EXPECT_THROW(Image(4, 4, {SpectralLayout{830, 360, 4}, false}), std::invalid_argument);
}

TEST(Image, BandCentresFollowTheBatchEdges) {
  Image img(1, 1, {SpectralLayout{360, 830, 4}, false});
  EXPECT_DOUBLE_EQ(img.band_center_nm(0), 418.75);
  EXPECT_DOUBLE_EQ(img.band_center_nm(1), 536.25);
  EXPECT_DOUBLE_EQ(img.band_center_nm(3), 771.25);
  EXPECT_DOUBLE_EQ(img.band_range(2).min_nm, batch_edge_nm(360, 830, 2, 4));
  EXPECT_THROW(img.band_center_nm(4), std::out_of_range);
  EXPECT_THROW(Image(1, 1).spectral_channel(0), std::logic_error);
}

TEST(Image, ResolveWritesTheTileIntoItsPlace) {
  Image img(6, 5, {SpectralLayout{400, 700, 2}, true});
  FilmTile tile(2, 1, 3, 2, 2);
  // Pixel (2, 1): two samples per batch of a D65 white, luminances 90, 110
  // (batch 0) and 270, 330 (batch 1) → Ȳ = 100 + 300 = 400.
  for (int b = 0; b < 2; ++b) {
    const double y = b == 0 ? 100.0 : 300.0;
    tile.add_sample(2, 1, b, d65_white(0.9 * y), 0.5 + b);
    tile.add_sample(2, 1, b, d65_white(1.1 * y), 1.5 + b);
  }
  // Pixel (3, 1): batch 1 has a single sample → mean known, error unknown.
  tile.add_sample(3, 1, 0, d65_white(10.0), 0.1);
  tile.add_sample(3, 1, 0, d65_white(10.0), 0.1);
  tile.add_sample(3, 1, 1, d65_white(20.0), 0.2);
  // Pixel (4, 2): no samples → RGB 0, error unknown.
  img.resolve(tile);

  const auto c = img.rgb(2, 1);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], 400.0f, 400.0f * 1e-6f);
  EXPECT_FLOAT_EQ(img.spectral(2, 1, 0), 1.0f);
  EXPECT_FLOAT_EQ(img.spectral(2, 1, 1), 2.0f);
  // s²_0 = 2·10²/1 = 200, s²_1 = 2·30²/1 = 1800; Var = 200/2 + 1800/2 = 1000.
  ASSERT_TRUE(img.relative_error(2, 1).has_value());
  EXPECT_NEAR(*img.relative_error(2, 1), std::sqrt(1000.0) / 400.0, 1e-6);
  EXPECT_NEAR(*img.relative_error(2, 1), *tile.relative_standard_error(2, 1), 1e-7);

  EXPECT_NEAR(img.luminance(3, 1), 30.0, 30.0 * 1e-6);
  EXPECT_FALSE(img.relative_error(3, 1).has_value());
  EXPECT_EQ(img.relative_error()[1 * 6 + 3], Image::kUnknownError);

  EXPECT_EQ(img.rgb(4, 2)[0], 0.0f);
  EXPECT_EQ(img.spectral(4, 2, 1), 0.0f);
  EXPECT_FALSE(img.relative_error(4, 2).has_value());
  // Outside the tile nothing changed.
  EXPECT_EQ(img.rgb(1, 1)[0], 0.0f);
  EXPECT_EQ(img.rgb(5, 1)[0], 0.0f);
  for (float v : img.relative_error()) EXPECT_FALSE(std::isnan(v));
}

TEST(Image, ResolveRejectsTilesThatDoNotFit) {
  Image img(4, 4, {SpectralLayout{400, 700, 2}, false});
  EXPECT_THROW(img.resolve(FilmTile(2, 2, 3, 2, 2)), std::invalid_argument);
  EXPECT_THROW(img.resolve(FilmTile(0, 0, 2, 2, 3)), std::invalid_argument);  // batch count differs
  Image rgb_only(4, 4);
  EXPECT_NO_THROW(rgb_only.resolve(FilmTile(0, 0, 4, 4, 5)));  // any batch count without spectral channels
}

TEST(Image, ResolveOfTheSameTileTwiceIsIdempotent) {
  Image img(2, 2, {std::nullopt, true});
  FilmTile t(0, 0, 2, 2, 1);
  for (int s = 0; s < 3; ++s) t.add_sample(1, 1, 0, Xyz{1.0, 2.0 + s, 3.0}, 0);
  img.resolve(t);
  const std::vector<float> first = img.rgb();
  img.resolve(t);
  EXPECT_EQ(img.rgb(), first);
}

}  // namespace
}  // namespace skyfarm
