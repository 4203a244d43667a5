#include "server/timelapse/timelapse_font.h"

#include <stdexcept>
#include <string>

namespace skyfarm::server {
namespace {

struct GlyphEntry {
  char c;
  Glyph rows;
};

// Drawn for this project: 5 columns (bit 4 = left), 7 rows.
constexpr GlyphEntry kGlyphs[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
    {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
    {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
    {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
    {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
    {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'-', {0x00, 0x00, 0x00, 0x0E, 0x00, 0x00, 0x00}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}},
    {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
    {' ', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
};

constexpr Glyph kMissing = {0x1F, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1F};

const GlyphEntry* find_glyph(char c) {
  for (const GlyphEntry& g : kGlyphs)
    if (g.c == c) return &g;
  return nullptr;
}

}  // namespace

Canvas8::Canvas8(int width, int height, Rgb8 background) : width_(width), height_(height) {
  if (width < 1 || height < 1)
    throw std::invalid_argument("Canvas8: size " + std::to_string(width) + " x " + std::to_string(height));
  rgb_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  for (std::size_t i = 0; i < rgb_.size(); i += 3) {
    rgb_[i] = background.r;
    rgb_[i + 1] = background.g;
    rgb_[i + 2] = background.b;
  }
}

void Canvas8::set(int x, int y, Rgb8 c) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  rgb_[i] = c.r;
  rgb_[i + 1] = c.g;
  rgb_[i + 2] = c.b;
}

Rgb8 Canvas8::at(int x, int y) const {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) throw std::out_of_range("Canvas8::at outside the canvas");
  const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

const Glyph& glyph_for(char c) {
  const GlyphEntry* g = find_glyph(c);
  return g ? g->rows : kMissing;
}

bool font_has(char c) { return find_glyph(c) != nullptr; }

int text_width(std::string_view text, int scale) {
  if (text.empty()) return 0;
  return (static_cast<int>(text.size()) * kGlyphAdvance - (kGlyphAdvance - kGlyphWidth)) * scale;
}

void draw_text(Canvas8& canvas, int x, int y, std::string_view text, Rgb8 colour, int scale) {
  for (std::size_t k = 0; k < text.size(); ++k) {
    const Glyph& g = glyph_for(text[k]);
    const int x0 = x + static_cast<int>(k) * kGlyphAdvance * scale;
    for (int row = 0; row < kGlyphHeight; ++row)
      for (int col = 0; col < kGlyphWidth; ++col) {
        if (!(g[static_cast<std::size_t>(row)] & (0x10 >> col))) continue;
        for (int dy = 0; dy < scale; ++dy)
          for (int dx = 0; dx < scale; ++dx) canvas.set(x0 + col * scale + dx, y + row * scale + dy, colour);
      }
  }
}

}  // namespace skyfarm::server
