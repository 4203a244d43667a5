#include "server/timelapse/timelapse_contact_sheet.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/image/png_writer.h"
#include "common/spectrum/color.h"

namespace skyfarm::server {
namespace {

// The display code of one linear component exposed by `scale` (png_writer.h).
std::uint8_t encode(double linear, double scale) {
  double v = scale * linear;
  v = std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0);
  return static_cast<std::uint8_t>(std::lround(srgb_encode(v) * 255.0));
}

// Source pixels [lo, hi) covered by destination pixel i of n over a source of
// `size` pixels: at least one (the nearest, when enlarging).
std::pair<int, int> footprint(int i, int n, int size) {
  const int lo = static_cast<int>(static_cast<long long>(i) * size / n);
  const int hi = static_cast<int>(static_cast<long long>(i + 1) * size / n);
  return {lo, std::max(hi, lo + 1)};
}

}  // namespace

int ContactSheetLayout::thumb_x(int i) const {
  const int cell_x = kPadding + (i % columns) * (cell_width + kPadding);
  return cell_x + (cell_width - thumb_width) / 2;
}

int ContactSheetLayout::thumb_y(int i) const { return kPadding + (i / columns) * (cell_height + kPadding); }

int ContactSheetLayout::label_x(int i, int text_px) const {
  const int cell_x = kPadding + (i % columns) * (cell_width + kPadding);
  return cell_x + std::max(0, (cell_width - text_px) / 2);
}

ContactSheetLayout contact_sheet_layout(int frames, int frame_width, int frame_height) {
  if (frames < 1 || frame_width < 1 || frame_height < 1)
    throw std::invalid_argument("contact sheet of " + std::to_string(frames) + " frames of " +
                                std::to_string(frame_width) + " x " + std::to_string(frame_height));
  ContactSheetLayout l;
  l.frames = frames;
  l.columns = std::min(frames, kMaxColumns);
  l.rows = (frames + l.columns - 1) / l.columns;
  if (frame_width >= frame_height) {
    l.thumb_width = kThumbBox;
    l.thumb_height = std::max(1, static_cast<int>(std::lround(double(kThumbBox) * frame_height / frame_width)));
  } else {
    l.thumb_height = kThumbBox;
    l.thumb_width = std::max(1, static_cast<int>(std::lround(double(kThumbBox) * frame_width / frame_height)));
  }
  l.cell_width = kThumbBox;
  l.cell_height = l.thumb_height + kLabelGap + kGlyphHeight;
  l.width = l.columns * l.cell_width + (l.columns + 1) * kPadding;
  l.height = l.rows * l.cell_height + (l.rows + 1) * kPadding;
  return l;
}

ContactSheet::ContactSheet(int frames, int frame_width, int frame_height)
    : layout_(contact_sheet_layout(frames, frame_width, frame_height)),
      canvas_(layout_.width, layout_.height, kBackground) {}

void ContactSheet::add(int index, const Image& frame, double ev100, std::string_view label) {
  if (index < 0 || index >= layout_.frames)
    throw std::out_of_range("contact sheet frame " + std::to_string(index) + " of " + std::to_string(layout_.frames));
  const double scale = exposure_scale(ev100);
  const int tw = layout_.thumb_width, th = layout_.thumb_height;
  const int x0 = layout_.thumb_x(index), y0 = layout_.thumb_y(index);
  for (int ty = 0; ty < th; ++ty) {
    const auto [sy0, sy1] = footprint(ty, th, frame.height());
    for (int tx = 0; tx < tw; ++tx) {
      const auto [sx0, sx1] = footprint(tx, tw, frame.width());
      double sum[3] = {0.0, 0.0, 0.0};
      for (int sy = sy0; sy < sy1; ++sy)
        for (int sx = sx0; sx < sx1; ++sx) {
          const auto c = frame.rgb(sx, sy);
          for (int k = 0; k < 3; ++k) sum[k] += static_cast<double>(c[static_cast<std::size_t>(k)]);
        }
      const double n = static_cast<double>((sy1 - sy0) * (sx1 - sx0));
      canvas_.set(x0 + tx, y0 + ty, {encode(sum[0] / n, scale), encode(sum[1] / n, scale), encode(sum[2] / n, scale)});
    }
  }
  const int px = text_width(label);
  draw_text(canvas_, layout_.label_x(index, px), layout_.label_y(index), label, kLabelColour);
}

void ContactSheet::write(const std::filesystem::path& path) const {
  write_png_rgb8(path, canvas_.width(), canvas_.height(), canvas_.rgb(),
                 {{std::string(kMetadataPrefix) + metadata_key::kContactSheetFrames, std::to_string(layout_.frames)},
                  {std::string(kMetadataPrefix) + metadata_key::kContactSheetColumns,
                   std::to_string(layout_.columns)}});
}

}  // namespace skyfarm::server
