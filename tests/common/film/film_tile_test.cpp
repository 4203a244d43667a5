// FilmTile: sums merge by elementwise addition (bit-identical in a fixed
// order), the wire format round-trips bit-exactly and rejects truncated and
// corrupt frames, and the per-pixel statistics match hand-computed values,
// including the sum over batches and the "unknown" case.
#include "common/film/film_tile.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace skyfarm {
namespace {

bool bit_equal(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

// A tile with random samples in every pixel and batch (deterministic).
FilmTile random_tile(std::uint32_t seed, int samples_per_pixel = 3) {
  FilmTile t(16, 8, 5, 4, 3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int b = 0; b < t.batches(); ++b)
    for (int y = t.y0(); y < t.y0() + t.height(); ++y)
      for (int x = t.x0(); x < t.x0() + t.width(); ++x)
        for (int s = 0; s < samples_per_pixel; ++s) {
          const Xyz c{1e3 * u(rng), 1e4 * u(rng) * u(rng), 1e2 * u(rng)};  // braces: left to right
          const double l = 0.1 * u(rng);
          t.add_sample(x, y, b, c, l);
        }
  return t;
}

TEST(FilmTile, AddSampleAccumulatesTheNineSums) {
  FilmTile t(10, 20, 2, 2, 2);
  t.add_sample(11, 21, 1, Xyz{1.0, 2.0, 3.0}, 0.5);
  t.add_sample(11, 21, 1, Xyz{4.0, 5.0, 6.0}, 0.25);
  const PixelBatchSums& s = t.sums(11, 21, 1);
  EXPECT_EQ(s.n, 2.0);
  EXPECT_EQ(s.sum_x, 5.0);
  EXPECT_EQ(s.sum_y, 7.0);
  EXPECT_EQ(s.sum_z, 9.0);
  EXPECT_EQ(s.sum_y2, 29.0);
  EXPECT_EQ(s.sum_l, 0.75);
  const Rgb a = xyz_to_linear_srgb(Xyz{1.0, 2.0, 3.0}), b = xyz_to_linear_srgb(Xyz{4.0, 5.0, 6.0});
  EXPECT_DOUBLE_EQ(s.sum_r2, a.r * a.r + b.r * b.r);
  EXPECT_DOUBLE_EQ(s.sum_g2, a.g * a.g + b.g * b.g);
  EXPECT_DOUBLE_EQ(s.sum_b2, a.b * a.b + b.b * b.b);
  EXPECT_EQ(t.sums(11, 21, 0).n, 0.0);  // the other batch is untouched
  EXPECT_EQ(t.sums(10, 20, 1).n, 0.0);  // and so is the other pixel
  EXPECT_EQ(t.total_samples(), 2.0);
}

TEST(FilmTile, RejectsBadGeometryAndOutOfRangePixels) {
  EXPECT_THROW(FilmTile(0, 0, 0, 4, 1), std::invalid_argument);
  EXPECT_THROW(FilmTile(0, 0, 4, 4, 0), std::invalid_argument);
  EXPECT_THROW(FilmTile(-1, 0, 4, 4, 1), std::invalid_argument);
  FilmTile t(4, 4, 2, 2, 2);
  EXPECT_THROW(t.add_sample(3, 4, 0, Xyz{1, 1, 1}, 1), std::out_of_range);
  EXPECT_THROW(t.add_sample(4, 6, 0, Xyz{1, 1, 1}, 1), std::out_of_range);
  EXPECT_THROW(t.add_sample(4, 4, 2, Xyz{1, 1, 1}, 1), std::out_of_range);
  EXPECT_THROW(t.mean_xyz(0, 0), std::out_of_range);
}

TEST(FilmTile, NonFiniteSamplesAreCountedNotAccumulated) {
  FilmTile t(0, 0, 1, 1, 1);
  t.add_sample(0, 0, 0, Xyz{1, 2, 3}, 4);
  t.add_sample(0, 0, 0, Xyz{std::numeric_limits<double>::quiet_NaN(), 2, 3}, 4);
  t.add_sample(0, 0, 0, Xyz{1, std::numeric_limits<double>::infinity(), 3}, 4);
  t.add_sample(0, 0, 0, Xyz{1, 2, 3}, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(t.rejected_samples(), 3u);
  EXPECT_EQ(t.sums(0, 0, 0).n, 1.0);
  EXPECT_EQ(t.sums(0, 0, 0).sum_y, 2.0);
}

// Hand-computed: batch 0 has Y = 1, 3 (mean 2, s² = ((1−2)² + (3−2)²)/1 = 2);
// batch 1 has Y = 10, 20, 30 (mean 20, s² = (100 + 0 + 100)/2 = 100).
// Whole-range mean Ȳ = 2 + 20 = 22 (batch means SUMMED);
// Var[Ȳ] = 2/2 + 100/3 = 34.333…; relative error sqrt(34.333…)/22.
TEST(FilmTile, MeanAndStandardErrorSumOverBatches) {
  FilmTile t(0, 0, 1, 1, 2);
  t.add_sample(0, 0, 0, Xyz{2, 1, 0.5}, 0.1);
  t.add_sample(0, 0, 0, Xyz{4, 3, 1.5}, 0.3);
  t.add_sample(0, 0, 1, Xyz{1, 10, 7}, 1.0);
  t.add_sample(0, 0, 1, Xyz{2, 20, 8}, 2.0);
  t.add_sample(0, 0, 1, Xyz{3, 30, 9}, 3.0);

  const auto mean = t.mean_xyz(0, 0);
  ASSERT_TRUE(mean.has_value());
  EXPECT_DOUBLE_EQ(mean->x, 3.0 + 2.0);
  EXPECT_DOUBLE_EQ(mean->y, 2.0 + 20.0);
  EXPECT_DOUBLE_EQ(mean->z, 1.0 + 8.0);

  EXPECT_DOUBLE_EQ(*t.band_radiance(0, 0, 0), 0.2);
  EXPECT_DOUBLE_EQ(*t.band_radiance(0, 0, 1), 2.0);
  EXPECT_DOUBLE_EQ(*t.luminance_sample_variance(0, 0, 0), 2.0);
  EXPECT_DOUBLE_EQ(*t.luminance_sample_variance(0, 0, 1), 100.0);

  const double var = 2.0 / 2.0 + 100.0 / 3.0;
  EXPECT_DOUBLE_EQ(*t.luminance_variance_of_mean(0, 0), var);
  EXPECT_DOUBLE_EQ(*t.relative_standard_error(0, 0), std::sqrt(var) / 22.0);
  EXPECT_EQ(t.min_batch_samples(0, 0), 2.0);
}

// Per-channel variance: samples whose linear sRGB is known exactly (built
// from RGB), so the expected variance is the textbook one per channel:
// batch 0 R = 1, 3 (s² = 2), G = 2, 2 (0), B = 0, 4 (8);
// batch 1 R = 10, 20, 30 (s² = 100), G = 1, 1, 1 (0), B = 5, 5, 8 (3).
TEST(FilmTile, RgbVarianceOfTheMeanPerChannel) {
  FilmTile t(0, 0, 1, 1, 2);
  auto add = [&](int b, double r, double g, double bl) {
    t.add_sample(0, 0, b, linear_srgb_to_xyz(Rgb{r, g, bl}), 0.0);
  };
  add(0, 1, 2, 0);
  EXPECT_FALSE(t.rgb_variance_of_mean(0, 0).has_value());  // n < 2 everywhere: unknown
  add(0, 3, 2, 4);
  add(1, 10, 1, 5);
  add(1, 20, 1, 5);
  EXPECT_TRUE(t.rgb_variance_of_mean(0, 0).has_value());
  add(1, 30, 1, 8);
  const auto var = t.rgb_variance_of_mean(0, 0);
  ASSERT_TRUE(var.has_value());
  // Round trips through XYZ cost a few ulps of the squares (values ~1e3).
  EXPECT_NEAR(var->r, 2.0 / 2.0 + 100.0 / 3.0, 1e-9);
  EXPECT_NEAR(var->g, 0.0, 1e-9);
  EXPECT_NEAR(var->b, 8.0 / 2.0 + 3.0 / 3.0, 1e-9);
}

TEST(FilmTile, TooFewSamplesIsUnknownNotZero) {
  FilmTile t(0, 0, 1, 1, 2);
  // No samples at all: nothing is known.
  EXPECT_FALSE(t.mean_xyz(0, 0).has_value());
  EXPECT_FALSE(t.relative_standard_error(0, 0).has_value());
  EXPECT_FALSE(t.band_radiance(0, 0, 0).has_value());

  // Batch 0 sampled twice, batch 1 not at all: the mean over the whole range
  // is unknown (half the spectrum is missing), so is the error.
  t.add_sample(0, 0, 0, Xyz{1, 1, 1}, 1);
  t.add_sample(0, 0, 0, Xyz{2, 2, 2}, 1);
  EXPECT_FALSE(t.mean_xyz(0, 0).has_value());
  EXPECT_TRUE(t.band_radiance(0, 0, 0).has_value());
  EXPECT_FALSE(t.band_radiance(0, 0, 1).has_value());
  EXPECT_FALSE(t.luminance_variance_of_mean(0, 0).has_value());

  // One sample in batch 1: the mean is known, the variance is not (n_b < 2).
  t.add_sample(0, 0, 1, Xyz{5, 5, 5}, 1);
  ASSERT_TRUE(t.mean_xyz(0, 0).has_value());
  EXPECT_DOUBLE_EQ(t.mean_xyz(0, 0)->y, 1.5 + 5.0);
  EXPECT_FALSE(t.luminance_sample_variance(0, 0, 1).has_value());
  EXPECT_FALSE(t.luminance_variance_of_mean(0, 0).has_value());
  EXPECT_FALSE(t.relative_standard_error(0, 0).has_value());

  // A second sample in batch 1: now it is known.
  t.add_sample(0, 0, 1, Xyz{7, 7, 7}, 1);
  ASSERT_TRUE(t.relative_standard_error(0, 0).has_value());
  EXPECT_TRUE(std::isfinite(*t.relative_standard_error(0, 0)));
}

TEST(FilmTile, EqualSamplesHaveZeroErrorEvenWhenBlack) {
  FilmTile t(0, 0, 2, 1, 2);
  for (int b = 0; b < 2; ++b)
    for (int s = 0; s < 4; ++s) {
      t.add_sample(0, 0, b, Xyz{0.1, 0.1, 0.1}, 0.2);  // not exact in binary
      t.add_sample(1, 0, b, Xyz{0, 0, 0}, 0);
    }
  EXPECT_EQ(*t.relative_standard_error(0, 0), 0.0);  // clamped, never negative or NaN
  EXPECT_EQ(*t.relative_standard_error(1, 0), 0.0);
  EXPECT_EQ(t.mean_xyz(1, 0)->y, 0.0);
}

TEST(FilmTile, MergeIsElementwiseAddition) {
  FilmTile a = random_tile(1), b = random_tile(2);
  const FilmTile a0 = a;
  a.merge(b);
  for (std::size_t i = 0; i < a.data().size(); ++i) {
    const PixelBatchSums &m = a.data()[i], &p = a0.data()[i], &q = b.data()[i];
    EXPECT_TRUE(bit_equal(m.n, p.n + q.n));
    EXPECT_TRUE(bit_equal(m.sum_x, p.sum_x + q.sum_x));
    EXPECT_TRUE(bit_equal(m.sum_y, p.sum_y + q.sum_y));
    EXPECT_TRUE(bit_equal(m.sum_z, p.sum_z + q.sum_z));
    EXPECT_TRUE(bit_equal(m.sum_y2, p.sum_y2 + q.sum_y2));
    EXPECT_TRUE(bit_equal(m.sum_l, p.sum_l + q.sum_l));
  }
}

TEST(FilmTile, MergingInTheSameOrderIsBitIdentical) {
  auto merged = [] {
    FilmTile acc(16, 8, 5, 4, 3);
    for (std::uint32_t seed : {11u, 12u, 13u, 14u}) acc.merge(random_tile(seed));
    return acc.serialize();
  };
  EXPECT_EQ(merged(), merged());
}

TEST(FilmTile, MergeOfOneUnitPerBatchEqualsTheWholeTile) {
  // Units of work fill one batch each; merged, they equal a tile that took
  // every sample itself (adding to zeros is exact).
  const FilmTile whole = random_tile(5);
  FilmTile acc(16, 8, 5, 4, 3);
  for (int b = 0; b < 3; ++b) {
    FilmTile unit(16, 8, 5, 4, 3);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int bb = 0; bb < 3; ++bb)
      for (int y = 8; y < 12; ++y)
        for (int x = 16; x < 21; ++x)
          for (int s = 0; s < 3; ++s) {
            const Xyz c{1e3 * u(rng), 1e4 * u(rng) * u(rng), 1e2 * u(rng)};
            const double l = 0.1 * u(rng);
            if (bb == b) unit.add_sample(x, y, bb, c, l);
          }
    acc.merge(unit);
  }
  EXPECT_EQ(acc.serialize(), whole.serialize());
}

TEST(FilmTile, MergeRejectsADifferentGeometry) {
  FilmTile a(0, 0, 4, 4, 2);
  EXPECT_THROW(a.merge(FilmTile(4, 0, 4, 4, 2)), std::invalid_argument);
  EXPECT_THROW(a.merge(FilmTile(0, 0, 4, 4, 3)), std::invalid_argument);
  EXPECT_THROW(a.merge(FilmTile(0, 0, 4, 5, 2)), std::invalid_argument);
}

TEST(FilmTile, SerializeRoundTripsBitExactly) {
  FilmTile t = random_tile(7);
  // Awkward values: −0, a subnormal, a huge sum, an exact integer count.
  t.add_sample(16, 8, 0, Xyz{-0.0, 4.9e-324, 1e150}, -0.0);
  t.add_sample(17, 8, 0, Xyz{std::numeric_limits<double>::infinity(), 0, 0}, 0);  // rejected, counted
  const std::vector<std::uint8_t> bytes = t.serialize();
  const FilmTile r = FilmTile::deserialize(bytes);
  EXPECT_TRUE(r.same_geometry(t));
  EXPECT_EQ(r.rejected_samples(), 1u);
  ASSERT_EQ(r.data().size(), t.data().size());
  for (std::size_t i = 0; i < t.data().size(); ++i) {
    EXPECT_TRUE(bit_equal(r.data()[i].n, t.data()[i].n));
    EXPECT_TRUE(bit_equal(r.data()[i].sum_x, t.data()[i].sum_x));
    EXPECT_TRUE(bit_equal(r.data()[i].sum_y, t.data()[i].sum_y));
    EXPECT_TRUE(bit_equal(r.data()[i].sum_z, t.data()[i].sum_z));
    EXPECT_TRUE(bit_equal(r.data()[i].sum_y2, t.data()[i].sum_y2));
    EXPECT_TRUE(bit_equal(r.data()[i].sum_l, t.data()[i].sum_l));
  }
  EXPECT_EQ(r.serialize(), bytes);
}

TEST(FilmTile, SerializedHeaderIsLittleEndianAndOmitsEmptyBatches) {
  FilmTile t(0x0102, 3, 2, 2, 4);
  t.add_sample(0x0102, 3, 2, Xyz{1, 2, 3}, 4);  // only batch 2 has data
  const std::vector<std::uint8_t> bytes = t.serialize();
  ASSERT_GE(bytes.size(), 44u);
  EXPECT_EQ(std::memcmp(bytes.data(), "SKFT", 4), 0);
  EXPECT_EQ(bytes[4], FilmTile::kFormatVersion);
  EXPECT_EQ(bytes[8], 0x02);
  EXPECT_EQ(bytes[9], 0x01);
  EXPECT_EQ(bytes[24], 4);  // batches
  EXPECT_EQ(bytes[28], 1);  // one present batch
  EXPECT_EQ(bytes[40 + 0], 0);
  EXPECT_EQ(bytes[40 + 2], 1);
  // 40-byte header, 4 flags, one batch of 2 × 2 records of 9 doubles, CRC.
  EXPECT_EQ(bytes.size(), 40u + 4u + 2u * 2u * 9u * 8u + 4u);
  const FilmTile r = FilmTile::deserialize(bytes);
  EXPECT_EQ(r.sums(0x0102, 3, 2).sum_z, 3.0);
  EXPECT_EQ(r.sums(0x0103, 4, 0).n, 0.0);
}

TEST(FilmTile, DeserializeRejectsEveryTruncation) {
  FilmTile t(0, 0, 2, 1, 2);
  t.add_sample(0, 0, 0, Xyz{1, 2, 3}, 4);
  t.add_sample(1, 0, 1, Xyz{5, 6, 7}, 8);
  const std::vector<std::uint8_t> bytes = t.serialize();
  for (std::size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(FilmTile::deserialize(bytes.data(), n), FilmTileDecodeError) << "prefix of " << n << " bytes";
  std::vector<std::uint8_t> longer = bytes;
  longer.push_back(0);
  EXPECT_THROW(FilmTile::deserialize(longer), FilmTileDecodeError);
  EXPECT_THROW(FilmTile::deserialize(nullptr, 0), FilmTileDecodeError);
}

TEST(FilmTile, DeserializeRejectsEverySingleBitFlip) {
  FilmTile t(0, 0, 2, 1, 2);
  t.add_sample(0, 0, 0, Xyz{1, 2, 3}, 4);
  t.add_sample(1, 0, 1, Xyz{5, 6, 7}, 8);
  const std::vector<std::uint8_t> bytes = t.serialize();
  for (std::size_t i = 0; i < bytes.size(); ++i)
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<std::uint8_t> bad = bytes;
      bad[i] ^= static_cast<std::uint8_t>(1u << bit);
      EXPECT_THROW(FilmTile::deserialize(bad), FilmTileDecodeError) << "byte " << i << " bit " << bit;
    }
}

TEST(FilmTile, DeserializeRejectsAHugeClaimedSizeWithoutAllocating) {
  FilmTile t(0, 0, 1, 1, 1);
  std::vector<std::uint8_t> bytes = t.serialize();
  // Width 65536 × height 65536: the size check fails before any allocation.
  bytes[16] = 0x00, bytes[17] = 0x00, bytes[18] = 0x01, bytes[19] = 0x00;
  bytes[20] = 0x00, bytes[21] = 0x00, bytes[22] = 0x01, bytes[23] = 0x00;
  EXPECT_THROW(FilmTile::deserialize(bytes), FilmTileDecodeError);
  // Width 2^31: over the limit.
  bytes[19] = 0x80;
  EXPECT_THROW(FilmTile::deserialize(bytes), FilmTileDecodeError);
  // Garbage that is not a tile at all.
  const std::vector<std::uint8_t> junk(100, 0xAB);
  try {
    FilmTile::deserialize(junk);
    FAIL() << "junk accepted";
  } catch (const FilmTileDecodeError& e) {
    EXPECT_NE(std::string(e.what()).find("magic"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace skyfarm
