// The contact sheet: its layout in numbers, thumbnails exposed and encoded as
// the frame PNGs are, in frame order, each frame's time readable under it;
// and the exposure smoothing over the sequence.
#include "server/timelapse/timelapse_contact_sheet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <unistd.h>

#include "common/image/png_writer.h"
#include "common/spectrum/color.h"
#include "server/timelapse/timelapse_exposure.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

// A frame of one linear grey level (cd/m^2).
Image grey_frame(int w, int h, float level) {
  Image image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.set_rgb(x, y, Rgb{level, level, level});
  return image;
}

// The label drawn at (x, y), read back glyph by glyph ('?' for no match).
std::string read_label(const Canvas8& c, int x, int y, std::size_t n) {
  std::string out;
  for (std::size_t k = 0; k < n; ++k) {
    char found = '?';
    for (char ch : std::string_view("0123456789-:T+Z. ")) {
      bool same = true;
      const Glyph& g = glyph_for(ch);
      for (int row = 0; row < kGlyphHeight && same; ++row)
        for (int col = 0; col < kGlyphWidth && same; ++col) {
          const bool ink = c.at(x + static_cast<int>(k) * kGlyphAdvance + col, y + row) == kLabelColour;
          same = ink == static_cast<bool>(g[static_cast<std::size_t>(row)] & (0x10 >> col));
        }
      if (same) found = ch;
    }
    out.push_back(found);
  }
  return out;
}

TEST(ContactSheetLayout, TheDocumentedNumbers) {
  // 4 frames of 16 x 8: one row of 4 cells of 192 x (96 + 4 + 7), 8 px around and between.
  const ContactSheetLayout four = contact_sheet_layout(4, 16, 8);
  EXPECT_EQ(four.columns, 4);
  EXPECT_EQ(four.rows, 1);
  EXPECT_EQ(four.thumb_width, 192);
  EXPECT_EQ(four.thumb_height, 96);
  EXPECT_EQ(four.width, 4 * 192 + 5 * 8);
  EXPECT_EQ(four.height, 96 + 4 + 7 + 2 * 8);
  // 13 square frames: 8 columns, 2 rows of 192 x 192 thumbnails.
  const ContactSheetLayout many = contact_sheet_layout(13, 512, 512);
  EXPECT_EQ(many.columns, 8);
  EXPECT_EQ(many.rows, 2);
  EXPECT_EQ(many.width, 8 * 192 + 9 * 8);
  EXPECT_EQ(many.height, 2 * (192 + 11) + 3 * 8);
  EXPECT_EQ(many.thumb_x(8), many.thumb_x(0)) << "frame 8 starts the second row";
  EXPECT_EQ(many.thumb_y(8), many.thumb_y(0) + 192 + 11 + 8);
  // A tall frame is fitted by its height and centred in the cell.
  const ContactSheetLayout tall = contact_sheet_layout(1, 100, 400);
  EXPECT_EQ(tall.thumb_width, 48);
  EXPECT_EQ(tall.thumb_height, 192);
  EXPECT_EQ(tall.thumb_x(0), 8 + (192 - 48) / 2);
  EXPECT_THROW(contact_sheet_layout(0, 16, 8), std::invalid_argument);
}

TEST(ContactSheet, ThumbnailsAreExposedLikeTheFramePngsAndLabelsReadBack) {
  const double ev = 10.0;
  const double scale = exposure_scale(ev);
  // Three frames at 10 %, 18 % and 50 % of white after exposure.
  const double shades[] = {0.10, 0.18, 0.50};
  const char* labels[] = {"2013-05-27T19:00:00-04:00", "2013-05-27T19:25:00-04:00", "2013-05-27T19:50:00-04:00"};
  ContactSheet sheet(3, 16, 8);
  for (int i = 0; i < 3; ++i) sheet.add(i, grey_frame(16, 8, static_cast<float>(shades[i] / scale)), ev, labels[i]);
  const ContactSheetLayout& l = sheet.layout();
  const Canvas8& c = sheet.canvas();
  for (int i = 0; i < 3; ++i) {
    const auto code = static_cast<std::uint8_t>(std::lround(srgb_encode(shades[i]) * 255.0));
    EXPECT_EQ(c.at(l.thumb_x(i), l.thumb_y(i)).g, code) << i;
    EXPECT_EQ(c.at(l.thumb_x(i) + l.thumb_width - 1, l.thumb_y(i) + l.thumb_height - 1).r, code) << i;
    EXPECT_EQ(c.at(l.thumb_x(i) - 1, l.thumb_y(i)), kBackground);
    const std::string label = labels[i];
    EXPECT_EQ(read_label(c, l.label_x(i, text_width(label)), l.label_y(i), label.size()), label);
  }
  // The written PNG has the layout's size and the same pixels.
  const fs::path path = fs::temp_directory_path() / ("skyfarm_sheet_" + std::to_string(::getpid()) + ".png");
  sheet.write(path);
  const PngFile png = read_png(path);
  EXPECT_EQ(png.width, l.width);
  EXPECT_EQ(png.height, l.height);
  EXPECT_EQ(png.bit_depth, 8);
  EXPECT_TRUE(png.has_srgb_chunk);
  for (std::size_t i = 0; i < c.rgb().size(); i += 997) EXPECT_EQ(png.rgb[i], c.rgb()[i]) << i;
  fs::remove(path);
}

TEST(ContactSheet, DownscalingAveragesInLinearLight) {
  // Half the columns black, half at level 2 x: the thumbnail pixel covering both is level x.
  Image frame(400, 200);
  const double scale = exposure_scale(8.0);
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 400; ++x) {
      const float v = x % 2 ? static_cast<float>(2 * 0.2 / scale) : 0.0f;
      frame.set_rgb(x, y, Rgb{v, v, v});
    }
  ContactSheet sheet(1, 400, 200);
  sheet.add(0, frame, 8.0, "");
  const auto expected = static_cast<std::uint8_t>(std::lround(srgb_encode(0.2) * 255.0));
  EXPECT_EQ(sheet.canvas().at(sheet.layout().thumb_x(0) + 5, sheet.layout().thumb_y(0) + 5).b, expected);
}

TEST(TimelapseExposure, SmoothingKeepsTrendsAndDampsJitter) {
  // A steady trend (the sky darkening) comes out unchanged, ends included.
  std::vector<double> trend;
  for (int i = 0; i < 9; ++i) trend.push_back(14.0 - 0.75 * i);
  const auto kept = smoothed_exposure(trend, 5);
  for (std::size_t i = 0; i < trend.size(); ++i) EXPECT_NEAR(kept[i], trend[i], 1e-12) << i;
  // Frame-to-frame jitter of +-0.3 EV around 12 shrinks inside the sequence.
  std::vector<double> jitter;
  for (int i = 0; i < 9; ++i) jitter.push_back(12.0 + (i % 2 ? 0.3 : -0.3));
  const auto damped = smoothed_exposure(jitter, 5);
  for (std::size_t i = 2; i + 2 < jitter.size(); ++i) EXPECT_LT(std::abs(damped[i] - 12.0), 0.1) << i;
  EXPECT_EQ(smoothed_exposure(jitter, 1), jitter);
  EXPECT_EQ(damped.front(), jitter.front()) << "the first frame keeps its own EV (centred window)";
  EXPECT_THROW(smoothed_exposure(jitter, 4), std::invalid_argument);
  EXPECT_TRUE(smoothed_exposure({}, 3).empty());
}

}  // namespace
}  // namespace skyfarm::server
