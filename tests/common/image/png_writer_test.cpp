// PNG output: the EV100 exposure convention, clamping and the sRGB transfer,
// 8- and 16-bit round trips, automatic exposure putting the median luminance
// at middle grey despite the sun, metadata, and clear errors.
#include "common/image/png_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/spectrum/color.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

class PngWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("skyfarm_png_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

int code8(double linear) { return static_cast<int>(std::lround(srgb_encode(std::clamp(linear, 0.0, 1.0)) * 255.0)); }
int code16(double linear) {
  return static_cast<int>(std::lround(srgb_encode(std::clamp(linear, 0.0, 1.0)) * 65535.0));
}

TEST(PngExposure, Ev100MapsTheMeteredLuminanceToMiddleGrey) {
  // EV100 = log2(L · 100 / 12.5): L = 2^EV / 8 maps to 0.18.
  EXPECT_DOUBLE_EQ(exposure_scale(3.0), 0.18);
  EXPECT_DOUBLE_EQ(exposure_scale(15.0) * 4096.0, 0.18);
  EXPECT_DOUBLE_EQ(exposure_scale(14.0) / exposure_scale(15.0), 2.0);  // one EV more = half as bright
}

TEST_F(PngWriterTest, FixedExposureEightBit) {
  Image img(4, 2);
  const double ev = 12.0, lm = std::exp2(ev - 3.0);  // 512 cd/m² → middle grey
  img.set_rgb(0, 0, Rgb{lm, lm, lm});
  img.set_rgb(1, 0, Rgb{0.5 * lm, 2.0 * lm, 0.1 * lm});
  img.set_rgb(2, 0, Rgb{1e9, 1e9, 1e9});  // the sun clips to white
  img.set_rgb(3, 0, Rgb{-5.0, 0.0, 4.0 * lm});  // negative clips to 0
  img.set_metadata(metadata_key::kRequest, std::string("{\"seed\":1}"));
  img.set_metadata(metadata_key::kSunZenithDeg, 48.5);
  const std::string long_value(5000, 'j');  // stored compressed
  img.set_metadata("long", long_value);
  const fs::path path = dir_ / "fixed.png";
  const PngWriteReport report = write_png(img, path, {.exposure_ev = ev});
  EXPECT_EQ(report.exposure_ev, ev);
  EXPECT_DOUBLE_EQ(report.scale, 0.18 / lm);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));

  const PngFile f = read_png(path);
  EXPECT_EQ(f.width, 4);
  EXPECT_EQ(f.height, 2);
  EXPECT_EQ(f.bit_depth, 8);
  EXPECT_TRUE(f.has_srgb_chunk);
  const auto px = [&](int x, int y, int c) { return f.rgb[(static_cast<std::size_t>(y) * 4 + x) * 3 + c]; };
  EXPECT_EQ(px(0, 0, 0), 118);  // sRGB(0.18) = 0.4614 → 118
  EXPECT_EQ(px(0, 0, 1), 118);
  EXPECT_EQ(px(1, 0, 0), code8(0.09));
  EXPECT_EQ(px(1, 0, 1), code8(0.36));
  EXPECT_EQ(px(1, 0, 2), code8(0.018));
  EXPECT_EQ(px(2, 0, 0), 255);
  EXPECT_EQ(px(3, 0, 0), 0);
  EXPECT_EQ(px(3, 0, 2), code8(0.72));
  EXPECT_EQ(px(0, 1, 0), 0);  // black stays black

  EXPECT_EQ(f.text.at("skyfarm:request"), "{\"seed\":1}");
  EXPECT_EQ(f.text.at("skyfarm:sun_zenith_deg"), "48.5");
  EXPECT_EQ(f.text.at("skyfarm:exposure_ev100"), "12");
  EXPECT_EQ(f.text.at("skyfarm:long"), long_value);
}

TEST_F(PngWriterTest, SixteenBit) {
  Image img(3, 1);
  const double lm = std::exp2(15.0 - 3.0);
  img.set_rgb(0, 0, Rgb{lm, 0.25 * lm, 3.0 * lm});
  img.set_rgb(1, 0, Rgb{1e-3 * lm, 0.0, 10.0 * lm});
  const fs::path path = dir_ / "sixteen.png";
  write_png(img, path, {.exposure_ev = 15.0, .bit_depth = 16});
  const PngFile f = read_png(path);
  EXPECT_EQ(f.bit_depth, 16);
  EXPECT_EQ(f.rgb[0], code16(0.18));
  EXPECT_EQ(f.rgb[1], code16(0.045));
  EXPECT_EQ(f.rgb[2], code16(0.54));
  EXPECT_EQ(f.rgb[3], code16(0.00018));  // the linear toe of the sRGB curve
  EXPECT_EQ(f.rgb[5], 65535);
}

TEST_F(PngWriterTest, AutomaticExposurePutsTheMedianAtMiddleGreyDespiteTheSun) {
  // A sky-like log-spread of luminances, a few sun-disk pixels at 1.6e9
  // cd/m², and unlit pixels (0) that must not count.
  Image img(32, 16);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) {
      const double l = 1000.0 * std::exp2((x + 32 * y) / 512.0 * 6.0 - 3.0);  // 125 … 8000 cd/m²
      img.set_rgb(x, y, Rgb{l, l, l});
    }
  for (int x = 0; x < 4; ++x) img.set_rgb(x, 0, Rgb{1.6e9, 1.6e9, 1.6e9});
  for (int x = 28; x < 32; ++x) img.set_rgb(x, 15, Rgb{0, 0, 0});

  const double ev = auto_exposure_ev(img);
  // The median over the 508 lit pixels: sorted, those are pixels 4 … 507 of
  // the ramp and 4 suns; index round(0.5 · 507) = 254 (253.5 rounds away
  // from 0) is ramp pixel 258.
  const double median = 1000.0 * std::exp2(258 / 512.0 * 6.0 - 3.0);
  EXPECT_NEAR(ev, std::log2(8.0 * median), 1e-6);

  const fs::path path = dir_ / "auto.png";
  const PngWriteReport report = write_png(img, path);
  EXPECT_NEAR(report.exposure_ev, ev, 1e-12);
  const PngFile f = read_png(path);
  const std::size_t i = 258 * 3;  // pixel (2, 8)
  EXPECT_NEAR(f.rgb[i], 118, 1);  // the median at middle grey
  EXPECT_EQ(f.rgb[0], 255);       // the sun clips
  // About as many pixels below middle grey as above it.
  int below = 0, above = 0;
  for (std::size_t p = 0; p < f.rgb.size(); p += 3) (f.rgb[p] < 118 ? below : above)++;
  EXPECT_NEAR(below, above, 16);
}

TEST_F(PngWriterTest, AllBlackImageUsesEvZero) {
  const Image img(3, 3);
  EXPECT_EQ(auto_exposure_ev(img), 0.0);
  const fs::path path = dir_ / "black.png";
  EXPECT_EQ(write_png(img, path).exposure_ev, 0.0);
  for (std::uint16_t v : read_png(path).rgb) EXPECT_EQ(v, 0);
}

TEST_F(PngWriterTest, BadOptionsAndUnwritablePaths) {
  const Image img(2, 2);
  PngWriteOptions bad_depth, bad_percentile;
  bad_depth.bit_depth = 12;
  bad_percentile.auto_percentile = 1.0;
  EXPECT_THROW(write_png(img, dir_ / "a.png", bad_depth), std::invalid_argument);
  EXPECT_THROW(write_png(img, dir_ / "a.png", bad_percentile), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir_ / "a.png"));

  const fs::path missing = dir_ / "no_such_dir" / "out.png";
  try {
    write_png(img, missing);
    FAIL() << "no error";
  } catch (const FileWriteError& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(missing));
  const fs::path target = dir_ / "is_a_dir.png";
  fs::create_directory(target);
  EXPECT_THROW(write_png(img, target), FileWriteError);
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_FALSE(fs::exists(target.string() + ".tmp"));

  // Disk full (the temporary file is a link to /dev/full).
  if (fs::exists("/dev/full")) {
    const fs::path full = dir_ / "full.png";
    fs::create_symlink("/dev/full", full.string() + ".tmp");
    try {
      write_png(img, full);
      ADD_FAILURE() << "no error";
    } catch (const FileWriteError& e) {
      EXPECT_NE(std::string(e.what()).find(full.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(full));
  }

  const fs::path junk = dir_ / "junk.png";
  std::ofstream(junk) << "not a png";
  EXPECT_THROW(read_png(junk), std::runtime_error);
  EXPECT_THROW(read_png(dir_ / "missing.png"), std::runtime_error);
}

}  // namespace
}  // namespace skyfarm
