// EXR output: HALF and FLOAT round trips, the Rec.709/D65 chromaticities and
// absolute-units attributes, metadata, spectral channels named after the
// spectral-OpenEXR layout (Fichet et al. 2021), the error layer, atomic
// writes and clear errors for unwritable paths.
#include "common/image/exr_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

class ExrWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("skyfarm_exr_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// A small image with a gradient, a negative (out-of-gamut) value and a sun.
Image test_image(ImageLayers layers = {}) {
  Image img(7, 5, layers);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) img.set_rgb(x, y, Rgb{1000.0 + 10 * x, 2000.0 + 100 * y, 0.5 * (x + 1) * (y + 1)});
  img.set_rgb(6, 4, Rgb{-3.5, 12.25, 0.0});
  img.set_rgb(0, 0, Rgb{1.6e9, 1.5e9, 1.2e9});  // the sun's disk: beyond HALF
  return img;
}

TEST(ExrSpectralChannelName, FollowsTheSpectralOpenExrLayout) {
  EXPECT_EQ(spectral_channel_name(536.25), "S0.536,250000nm");
  EXPECT_EQ(spectral_channel_name(400.0), "S0.400,000000nm");
  EXPECT_EQ(spectral_channel_name(418.75), "S0.418,750000nm");
}

TEST_F(ExrWriterTest, FloatRoundTripKeepsAbsoluteValuesAndAttributes) {
  Image img = test_image();
  img.set_metadata(metadata_key::kRequest, std::string(R"({"camera":{"width":7,"height":5}})"));
  img.set_metadata(metadata_key::kSunZenithDeg, 48.9);
  img.set_metadata(metadata_key::kSamplesPerPixel, 64.0);
  const fs::path path = dir_ / "float.exr";
  const ExrWriteReport report = write_exr(img, path, {.half = false});
  EXPECT_EQ(report.clamped_half_values, 0u);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));

  const ExrFile f = read_exr(path);
  EXPECT_EQ(f.width, 7);
  EXPECT_EQ(f.height, 5);
  ASSERT_EQ(f.channels.size(), 3u);
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const ExrChannel& ch = f.channels.at(names[c]);
    EXPECT_EQ(ch.type, ExrPixelType::kFloat);
    for (std::size_t i = 0; i < img.pixel_count(); ++i) EXPECT_EQ(ch.values[i], img.rgb()[3 * i + c]) << i;
  }
  EXPECT_EQ(f.channels.at("R").values[0], 1.6e9f);  // the sun survives in FLOAT
  EXPECT_EQ(f.channels.at("R").values[34], -3.5f);  // out of gamut kept

  ASSERT_TRUE(f.chromaticities.has_value());
  const auto& chr = *f.chromaticities;
  EXPECT_FLOAT_EQ(chr[0].x, 0.64f);
  EXPECT_FLOAT_EQ(chr[0].y, 0.33f);
  EXPECT_FLOAT_EQ(chr[1].x, 0.30f);
  EXPECT_FLOAT_EQ(chr[1].y, 0.60f);
  EXPECT_FLOAT_EQ(chr[2].x, 0.15f);
  EXPECT_FLOAT_EQ(chr[2].y, 0.06f);
  EXPECT_FLOAT_EQ(chr[3].x, 0.3127f);
  EXPECT_FLOAT_EQ(chr[3].y, 0.3290f);
  EXPECT_EQ(f.number_attributes.at("whiteLuminance"), 1.0);

  EXPECT_EQ(f.string_attributes.at("skyfarm:request"), R"({"camera":{"width":7,"height":5}})");
  EXPECT_EQ(f.number_attributes.at("skyfarm:sun_zenith_deg"), 48.9);
  EXPECT_EQ(f.number_attributes.at("skyfarm:samples_per_pixel"), 64.0);
  EXPECT_TRUE(f.string_attributes.count("skyfarm:software_version"));
  EXPECT_FALSE(f.string_attributes.count("spectralLayoutVersion"));  // no spectral channels
  EXPECT_FALSE(f.number_attributes.count("skyfarm:half_clamped_values"));
}

TEST_F(ExrWriterTest, HalfRoundTripIsWithinHalfPrecisionAndClampsTheSun) {
  const Image img = test_image();
  const fs::path path = dir_ / "half.exr";
  const ExrWriteReport report = write_exr(img, path);  // HALF is the default
  EXPECT_EQ(report.clamped_half_values, 3u);           // the sun's R, G, B

  const ExrFile f = read_exr(path);
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const ExrChannel& ch = f.channels.at(names[c]);
    EXPECT_EQ(ch.type, ExrPixelType::kHalf);
    for (std::size_t i = 1; i < img.pixel_count(); ++i) {
      const float v = img.rgb()[3 * i + c];
      EXPECT_NEAR(ch.values[i], v, std::abs(v) * 1.0f / 1024.0f + 1e-4f) << names[c] << " " << i;
    }
    EXPECT_EQ(ch.values[0], kHalfMax);  // clamped, not infinite
  }
  EXPECT_EQ(f.number_attributes.at("skyfarm:half_clamped_values"), 3.0);
  ASSERT_TRUE(f.chromaticities.has_value());
}

TEST_F(ExrWriterTest, TallImagesAreWrittenInBlocksOfRows) {
  Image img(3, 150);  // more rows than one staging block
  for (int y = 0; y < 150; ++y) img.set_rgb(1, y, Rgb{double(y), 2.0 * y, 0.25});
  const fs::path path = dir_ / "tall.exr";
  write_exr(img, path);
  const ExrFile f = read_exr(path);
  for (int y = 0; y < 150; ++y) {
    EXPECT_EQ(f.channels.at("R").values[static_cast<std::size_t>(y) * 3 + 1], float(y)) << y;
    EXPECT_EQ(f.channels.at("G").values[static_cast<std::size_t>(y) * 3 + 1], float(2 * y)) << y;
  }
}

TEST_F(ExrWriterTest, SpectralChannelsAndErrorLayer) {
  Image img(4, 3, {SpectralLayout{360, 830, 4}, true});
  FilmTile t(0, 0, 4, 3, 4);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x)
      for (int b = 0; b < 4; ++b)
        for (int s = 0; s < (x == 3 ? 1 : 2); ++s)  // column 3: too few samples
          t.add_sample(x, y, b, Xyz{10.0 + s, 20.0 + 2 * s + x, 5.0}, 0.01 * (b + 1) + 0.001 * x + 0.002 * s);
  img.resolve(t);
  const fs::path path = dir_ / "spectral.exr";
  write_exr(img, path, {.half = true});

  const ExrFile f = read_exr(path);
  const char* expected[4] = {"S0.418,750000nm", "S0.536,250000nm", "S0.653,750000nm", "S0.771,250000nm"};
  for (int b = 0; b < 4; ++b) {
    ASSERT_TRUE(f.channels.count(expected[b])) << expected[b];
    const ExrChannel& ch = f.channels.at(expected[b]);
    EXPECT_EQ(ch.type, ExrPixelType::kFloat);
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) EXPECT_EQ(ch.values[static_cast<std::size_t>(y) * 4 + x], img.spectral(x, y, b));
  }
  EXPECT_EQ(f.string_attributes.at("spectralLayoutVersion"), "1.0");
  EXPECT_EQ(f.string_attributes.at("emissiveUnits"), "W.m^-2.sr^-1");
  EXPECT_EQ(f.string_attributes.at("skyfarm:spectral_band_edges_nm"), "360,477.5,595,712.5,830");

  ASSERT_TRUE(f.channels.count(kExrErrorChannel));
  const ExrChannel& err = f.channels.at(kExrErrorChannel);
  EXPECT_EQ(err.type, ExrPixelType::kFloat);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 3; ++x) {
      const float e = err.values[static_cast<std::size_t>(y) * 4 + x];
      EXPECT_TRUE(std::isfinite(e));
      EXPECT_FLOAT_EQ(e, static_cast<float>(*t.relative_standard_error(x, y)));
    }
    EXPECT_TRUE(std::isinf(err.values[static_cast<std::size_t>(y) * 4 + 3]));  // unknown, documented as +inf
  }
  EXPECT_TRUE(f.string_attributes.count("skyfarm:error.Y"));
  EXPECT_EQ(f.channels.size(), 3u + 4u + 1u);
}

TEST_F(ExrWriterTest, OptionalLayersCanBeLeftOut) {
  const Image img(2, 2, {SpectralLayout{400, 700, 3}, true});
  const fs::path path = dir_ / "rgb_only.exr";
  write_exr(img, path, {.spectral_channels = false, .error_layer = false, .compression = ExrCompression::kPiz});
  const ExrFile f = read_exr(path);
  EXPECT_EQ(f.channels.size(), 3u);
  EXPECT_FALSE(f.string_attributes.count("spectralLayoutVersion"));
}

TEST_F(ExrWriterTest, RewritingReplacesTheFileWhole) {
  const fs::path path = dir_ / "again.exr";
  Image a(2, 2), b(2, 2);
  a.set_rgb(0, 0, Rgb{1, 1, 1});
  b.set_rgb(0, 0, Rgb{2, 2, 2});
  write_exr(a, path);
  write_exr(b, path);
  EXPECT_EQ(read_exr(path).channels.at("G").values[0], 2.0f);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

TEST_F(ExrWriterTest, UnwritablePathsGiveAClearErrorAndNoFile) {
  const Image img = test_image();
  // A directory that does not exist.
  const fs::path missing = dir_ / "no_such_dir" / "out.exr";
  try {
    write_exr(img, missing);
    FAIL() << "no error";
  } catch (const FileWriteError& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(missing));
  // A "directory" that is a regular file (ENOTDIR, whoever runs the test).
  const fs::path file = dir_ / "plain_file";
  std::ofstream(file) << "x";
  EXPECT_THROW(write_exr(img, file / "out.exr"), FileWriteError);
  // The target is a directory: the temporary file is written, the rename
  // fails; the temporary file is removed and the directory is untouched.
  const fs::path target = dir_ / "target_is_a_dir.exr";
  fs::create_directory(target);
  EXPECT_THROW(write_exr(img, target), FileWriteError);
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_FALSE(fs::exists(target.string() + ".tmp"));
}

// Disk full: the temporary file is a link to /dev/full, where every write
// fails with ENOSPC.  The error names the path; no file appears at it, and
// the temporary link is removed.
TEST_F(ExrWriterTest, DiskFullGivesAClearErrorAndNoFile) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path path = dir_ / "full.exr";
  fs::create_symlink("/dev/full", path.string() + ".tmp");
  try {
    write_exr(test_image(), path, {.half = false});
    FAIL() << "no error";
  } catch (const FileWriteError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(fs::symlink_status(path.string() + ".tmp")));
}

TEST_F(ExrWriterTest, ReadingAMissingOrBrokenFileNamesIt) {
  const fs::path path = dir_ / "missing.exr";
  try {
    read_exr(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  const fs::path junk = dir_ / "junk.exr";
  std::ofstream(junk) << "not an exr";
  EXPECT_THROW(read_exr(junk), std::runtime_error);
}

}  // namespace
}  // namespace skyfarm
