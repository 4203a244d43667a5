#include "common/film/error_estimate.h"

#include <algorithm>
#include <cmath>

namespace skyfarm {

std::optional<double> ErrorSums::relative_rms() const {
  if (!(sum_Y2 > 0.0)) return std::nullopt;
  return std::sqrt(sum_var / sum_Y2);
}

ErrorSums error_sums(const FilmTile& tile, const std::vector<std::uint32_t>& excluded, int image_width) {
  ErrorSums s;
  for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y)
    for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x) {
      if (!excluded.empty() &&
          std::binary_search(excluded.begin(), excluded.end(),
                             static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(image_width) +
                                 static_cast<std::uint32_t>(x)))
        continue;
      const auto mean = tile.mean_xyz(x, y);
      if (!mean) continue;  // never traced (outside a fisheye circle)
      const auto var = tile.luminance_variance_of_mean(x, y);
      if (!var) {
        ++s.unknown;
        continue;
      }
      s.sum_var += *var;
      s.sum_Y2 += mean->y * mean->y;
    }
  return s;
}

}  // namespace skyfarm
