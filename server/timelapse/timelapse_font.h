// A tiny bitmap font and an 8-bit canvas to draw it on, for the timestamps
// under a timelapse's contact-sheet thumbnails (timelapse_contact_sheet.h).
//
// Parameters
//   glyphs   5 x 7 pixels, one column of spacing (advance 6 px per character):
//            the digits 0-9 and - : T + Z . and space, which is everything an
//            ISO 8601 time with an offset needs ("2013-05-27T09:30:00.250-04:00").
//            Any other character is drawn as a hollow 5 x 7 box, so a missing
//            glyph shows instead of vanishing.
//   scale    each font pixel becomes scale x scale canvas pixels (1 by default)
// Drawing clips at the canvas edges.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

namespace skyfarm::server {

struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb8&) const = default;
};

// Display-space 8-bit RGB pixels, interleaved, top row first.
class Canvas8 {
 public:
  Canvas8(int width, int height, Rgb8 background);
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<std::uint8_t>& rgb() const { return rgb_; }
  // Outside the canvas: set ignores the pixel, at throws std::out_of_range.
  void set(int x, int y, Rgb8 c);
  Rgb8 at(int x, int y) const;

 private:
  int width_, height_;
  std::vector<std::uint8_t> rgb_;
};

inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 7;
inline constexpr int kGlyphAdvance = 6;

// Rows top to bottom; bit 4 is the leftmost column.
using Glyph = std::array<std::uint8_t, kGlyphHeight>;

// The glyph of `c`, or the hollow box for a character the font lacks.
const Glyph& glyph_for(char c);
bool font_has(char c);

// Width in pixels of `text` drawn at `scale` (0 for empty text).
int text_width(std::string_view text, int scale = 1);
// Draws `text` with its top-left corner at (x, y).
void draw_text(Canvas8& canvas, int x, int y, std::string_view text, Rgb8 colour, int scale = 1);

}  // namespace skyfarm::server
