// A timelapse's frame PNGs (server/timelapse/timelapse_outputs.h) from frame
// EXRs written in another colour space and other units (output.color_space,
// output.units): each frame is read back to linear Rec.709 in cd/m² by its
// own attributes, so its PNG is the one the default EXR gives (to one 8-bit
// code: float rounding of the round trip); output.view reaches the frames.
#include "server/timelapse/timelapse_outputs.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

class TimelapseOutputsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("skyfarm_tl_outputs_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Two frames of a sky-like gradient with a bright, saturated sun, written
  // with `options`; their outputs built under dir_/name (no ffmpeg: no video).
  fs::path frames_and_outputs(const std::string& name, const ExrWriteOptions& options, DisplayView view) {
    const fs::path d = dir_ / name;
    fs::create_directories(d);
    std::vector<FrameInput> inputs;
    for (int f = 0; f < 2; ++f) {
      Image image(16, 8);
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x)
          image.set_rgb(x, y, Rgb{400.0 + 50 * x + 100 * f, 600.0 + 80 * y, 1500.0 - 60 * y});
      image.set_rgb(3, 6, Rgb{9e4, 2.5e4, -300.0});
      // (std::string::append: operator+ on a literal trips a GCC 12 -Wrestrict false positive.)
      std::string stem = "frame";
      stem.append(std::to_string(f));
      inputs.push_back({d / stem.append(".exr"), std::to_string(f)});
      write_exr(image, inputs.back().exr, options);
    }
    OutputSettings settings;
    settings.fixed_ev100 = 12.0;
    settings.view = view;
    settings.ffmpeg = (d / "no-ffmpeg").string();
    const std::atomic<bool> stop{false};
    const OutputsReport report = build_timelapse_outputs(inputs, settings, d, stop);
    EXPECT_FALSE(report.video);
    return d;
  }
  fs::path dir_;
};

TEST_F(TimelapseOutputsTest, FramesInOtherSpacesAndUnitsGiveTheDefaultFramesPngs) {
  const fs::path plain = frames_and_outputs("plain", {.half = false}, DisplayView::kSrgb);
  const fs::path managed = frames_and_outputs(
      "managed", {.half = false, .color_space = ColorSpace::kAcesCg, .units = RadiometricUnits::kRelative},
      DisplayView::kSrgb);
  for (int f = 0; f < 2; ++f) {
    const PngFile a = read_png(frame_png_path(plain, f)), b = read_png(frame_png_path(managed, f));
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    int worst = 0, lit = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
      worst = std::max(worst, std::abs(int(a.rgb[i]) - int(b.rgb[i])));
      lit += a.rgb[i] > 0 && a.rgb[i] < 255;
    }
    EXPECT_LE(worst, 1) << "frame " << f;
    EXPECT_GT(lit, 0);
    // The frame's PNG describes linear Rec.709 light: no leftover colour-space text.
    EXPECT_FALSE(b.text.contains("skyfarm:color_space"));
    EXPECT_FALSE(b.text.contains("skyfarm:units_scale"));
  }
  const fs::path aces = frames_and_outputs("aces", {.half = false}, DisplayView::kAces);
  const PngFile filmic = read_png(frame_png_path(aces, 0)), clipped = read_png(frame_png_path(plain, 0));
  EXPECT_EQ(filmic.text.at("skyfarm:view"), "aces");
  EXPECT_NE(filmic.rgb, clipped.rgb);
}

}  // namespace
}  // namespace skyfarm::server
