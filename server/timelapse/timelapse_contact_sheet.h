// A timelapse's contact sheet: every frame as a thumbnail in a grid, in frame
// order (row-major), each frame's timestamp drawn under it in the 5 x 7 font
// (timelapse_font.h).
//
// Layout (pixels; a pure function of the frame count and the frames' size):
//   thumbnail    the frame fitted into a kThumbBox x kThumbBox box, aspect kept
//                (a 2:1 equirect: 192 x 96; a square fisheye: 192 x 192),
//                each side at least 1
//   cell         kThumbBox wide (the widest label, 29 characters, is 173 px),
//                thumbnail height + kLabelGap + kGlyphHeight high; the
//                thumbnail is centred at the cell's top, the label centred
//                under it
//   grid         columns = min(frames, kMaxColumns), rows = ceil(frames /
//                columns), kPadding between cells and around the grid:
//                width  = columns * kThumbBox + (columns + 1) * kPadding
//                height = rows * cell height + (rows + 1) * kPadding
// e.g. 4 frames of 16 x 8: 4 x 1 cells, 808 x 123 pixels.
//
// Pixels: a thumbnail pixel is the mean of the linear RGB of the frame pixels
// it covers (nearest pixel when enlarging), exposed and encoded exactly as the
// frame PNGs are (png_writer.h: scale = exposure_scale(EV100), clip to [0, 1],
// sRGB transfer, 8 bits).  Background kBackground, labels kLabelColour.
// Memory: the whole sheet is held as 8-bit RGB (1000 frames of 2:1: ~70 MB).
#pragma once
#include <filesystem>
#include <string_view>

#include "common/film/image.h"
#include "server/timelapse/timelapse_font.h"

namespace skyfarm::server {

inline constexpr int kThumbBox = 192;
inline constexpr int kMaxColumns = 8;
inline constexpr int kPadding = 8;
inline constexpr int kLabelGap = 4;
inline constexpr Rgb8 kBackground{24, 24, 24};
inline constexpr Rgb8 kLabelColour{235, 235, 235};

struct ContactSheetLayout {
  int frames = 0;
  int columns = 0, rows = 0;
  int thumb_width = 0, thumb_height = 0;
  int cell_width = 0, cell_height = 0;
  int width = 0, height = 0;

  // Top-left corner of frame i's thumbnail, and the top of its label.
  int thumb_x(int i) const;
  int thumb_y(int i) const;
  int label_y(int i) const { return thumb_y(i) + thumb_height + kLabelGap; }
  // Left edge of a label `text_px` wide centred in frame i's cell.
  int label_x(int i, int text_px) const;
};

// Throws std::invalid_argument unless frames >= 1 and both sides >= 1.
ContactSheetLayout contact_sheet_layout(int frames, int frame_width, int frame_height);

class ContactSheet {
 public:
  ContactSheet(int frames, int frame_width, int frame_height);
  const ContactSheetLayout& layout() const { return layout_; }
  const Canvas8& canvas() const { return canvas_; }

  // Frame `index`'s thumbnail (its linear image exposed at ev100) and label.
  void add(int index, const Image& frame, double ev100, std::string_view label);
  // Writes the sheet as an 8-bit sRGB PNG, atomically; FileWriteError on failure.
  void write(const std::filesystem::path& path) const;

 private:
  ContactSheetLayout layout_;
  Canvas8 canvas_;
};

}  // namespace skyfarm::server
