#include "common/image/png_thumbnail.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "common/image/png_writer.h"
#include "common/spectrum/color.h"

namespace skyfarm {

void write_png_thumbnail(const std::filesystem::path& source, const std::filesystem::path& target, int width) {
  if (width < 1) throw std::invalid_argument("a thumbnail is at least 1 pixel wide");
  const PngFile png = read_png(source);
  const int sw = png.width, sh = png.height;
  const int w = std::min(width, sw);
  const int h = std::max(1, static_cast<int>(std::lround(static_cast<double>(sh) * w / sw)));
  const double max_code = png.bit_depth == 16 ? 65535.0 : 255.0;
  // One decoding table per code value (256 or 65536 entries).
  std::vector<double> linear(static_cast<std::size_t>(max_code) + 1);
  for (std::size_t c = 0; c < linear.size(); ++c) linear[c] = srgb_decode(static_cast<double>(c) / max_code);
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
  // Source columns [x0, x1) of thumbnail column x: the pixels whose centres
  // (i + 0.5) lie in [x sw / w, (x + 1) sw / w); never empty as w <= sw.
  auto span = [](int i, int n_out, int n_in) {
    const auto lo = static_cast<int>(std::ceil((static_cast<double>(i) * n_in) / n_out - 0.5));
    const auto hi = static_cast<int>(std::ceil((static_cast<double>(i + 1) * n_in) / n_out - 0.5));
    return std::pair<int, int>{std::clamp(lo, 0, n_in - 1), std::clamp(std::max(hi, lo + 1), 1, n_in)};
  };
  for (int y = 0; y < h; ++y) {
    const auto [y0, y1] = span(y, h, sh);
    for (int x = 0; x < w; ++x) {
      const auto [x0, x1] = span(x, w, sw);
      double sum[3] = {0, 0, 0};
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx)
          for (int c = 0; c < 3; ++c)
            sum[c] += linear[png.rgb[(static_cast<std::size_t>(sy) * sw + sx) * 3 + c]];
      const double n = static_cast<double>(y1 - y0) * (x1 - x0);
      for (int c = 0; c < 3; ++c) {
        const double code = std::round(srgb_encode(sum[c] / n) * 255.0);
        rgb[(static_cast<std::size_t>(y) * w + x) * 3 + c] = static_cast<std::uint8_t>(std::clamp(code, 0.0, 255.0));
      }
    }
  }
  write_png_rgb8(target, w, h, rgb, png.text);
}

}  // namespace skyfarm
