#include "common/film/error_estimate.h"

#include <cmath>

namespace skyfarm {

std::optional<double> ErrorSums::relative_rms() const {
  if (!(sum_Y2 > 0.0)) return std::nullopt;
  return std::sqrt(sum_var / sum_Y2);
}

ErrorSums error_sums(const FilmTile& tile) {
  ErrorSums s;
  for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y)
    for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x) {
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
