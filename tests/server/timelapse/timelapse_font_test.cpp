// The contact sheet's 5 x 7 font: every glyph a timestamp needs exists and is
// distinct, text drawn is read back character for character from the pixels,
// widths, scaling, clipping, and the box for a missing glyph.
#include "server/timelapse/timelapse_font.h"

#include <gtest/gtest.h>

#include <string>

namespace skyfarm::server {
namespace {

constexpr Rgb8 kInk{255, 255, 255};
constexpr Rgb8 kPaper{0, 0, 0};
constexpr std::string_view kCharset = "0123456789-:T+Z. ";

// The 5 x 7 bit pattern at (x, y) in the canvas (ink = set).
Glyph pattern_at(const Canvas8& c, int x, int y) {
  Glyph g{};
  for (int row = 0; row < kGlyphHeight; ++row)
    for (int col = 0; col < kGlyphWidth; ++col)
      if (c.at(x + col, y + row) == kInk) g[static_cast<std::size_t>(row)] |= static_cast<std::uint8_t>(0x10 >> col);
  return g;
}

// Reads `n` characters drawn at (x, y) back from the pixels ('?' when no glyph matches).
std::string read_back(const Canvas8& c, int x, int y, std::size_t n) {
  std::string out;
  for (std::size_t k = 0; k < n; ++k) {
    const Glyph g = pattern_at(c, x + static_cast<int>(k) * kGlyphAdvance, y);
    char found = '?';
    for (char ch : kCharset)
      if (glyph_for(ch) == g) found = ch;
    out.push_back(found);
  }
  return out;
}

TEST(TimelapseFont, EveryTimestampCharacterHasADistinctGlyph) {
  for (char a : kCharset) {
    EXPECT_TRUE(font_has(a)) << a;
    for (char b : kCharset) {
      if (a != b) {
        EXPECT_NE(glyph_for(a), glyph_for(b)) << a << " and " << b;
      }
    }
  }
  EXPECT_FALSE(font_has('x'));
  for (std::uint8_t row : glyph_for('8')) EXPECT_EQ(row & ~0x1F, 0) << "glyphs are 5 columns wide";
}

TEST(TimelapseFont, DrawnTimestampsReadBackExactly) {
  for (const std::string text : {"2013-05-27T09:30:00-04:00", "2021-06-22T00:00:00.500Z", "1999-12-31T23:59:59+05:30"}) {
    Canvas8 canvas(text_width(text) + 4, kGlyphHeight + 4, kPaper);
    draw_text(canvas, 2, 2, text, kInk);
    EXPECT_EQ(read_back(canvas, 2, 2, text.size()), text);
    // Nothing outside the text's box.
    for (int x = 0; x < canvas.width(); ++x) {
      EXPECT_EQ(canvas.at(x, 0), kPaper);
      EXPECT_EQ(canvas.at(x, canvas.height() - 1), kPaper);
    }
  }
}

TEST(TimelapseFont, WidthsAndScale) {
  EXPECT_EQ(text_width(""), 0);
  EXPECT_EQ(text_width("1"), 5);
  EXPECT_EQ(text_width("12:30"), 29);
  EXPECT_EQ(text_width("2013-05-27T09:30:00.250-04:00"), 173);
  EXPECT_EQ(text_width("12", 3), 33);
  Canvas8 canvas(40, 30, kPaper);
  draw_text(canvas, 0, 0, "T", kInk, 3);
  // The T's bar: 5 font pixels = 15 canvas pixels on rows 0..2; its stem at columns 6..8.
  for (int x = 0; x < 15; ++x) EXPECT_EQ(canvas.at(x, 2), kInk) << x;
  EXPECT_EQ(canvas.at(15, 0), kPaper);
  EXPECT_EQ(canvas.at(7, 20), kInk);
  EXPECT_EQ(canvas.at(5, 20), kPaper);
  EXPECT_EQ(canvas.at(7, 21), kPaper) << "7 font rows x 3 = 21 canvas rows";
}

TEST(TimelapseFont, MissingGlyphsAreBoxesAndDrawingClips) {
  Canvas8 canvas(8, 9, kPaper);
  draw_text(canvas, 1, 1, "x", kInk);
  EXPECT_EQ(pattern_at(canvas, 1, 1), (Glyph{0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F}));
  Canvas8 small(3, 3, kPaper);
  draw_text(small, -2, -2, "8888", kInk);  // partly outside: no crash, some ink inside
  int ink = 0;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) ink += small.at(x, y) == kInk;
  EXPECT_GT(ink, 0);
  EXPECT_THROW(small.at(3, 0), std::out_of_range);
  EXPECT_THROW(Canvas8(0, 1, kPaper), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm::server
