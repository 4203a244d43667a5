#include "common/film/error_estimate.h"

#include <algorithm>
#include <cmath>

namespace skyfarm {
namespace {

// sqrt(sum var / sum Y^2) with the true sum Y^2 estimated from the film's:
// sum Y^2 - sum var, at least kMinSignalShare of it (the header says why).
double relative_rms_of(double sum_var, double sum_film2) {
  const double sum_true2 = std::max(sum_film2 - sum_var, ErrorSums::kMinSignalShare * sum_film2);
  return std::sqrt(sum_var / sum_true2);
}

}  // namespace

std::optional<double> ErrorSums::relative_rms() const {
  if (!(sum_Y2 > 0.0)) return std::nullopt;
  return relative_rms_of(sum_var, sum_Y2);
}

std::optional<Rgb> ErrorSums::relative_rms_rgb() const {
  if (!(sum_rgb2.r > 0.0) || !(sum_rgb2.g > 0.0) || !(sum_rgb2.b > 0.0)) return std::nullopt;
  return Rgb{relative_rms_of(sum_var_rgb.r, sum_rgb2.r), relative_rms_of(sum_var_rgb.g, sum_rgb2.g),
             relative_rms_of(sum_var_rgb.b, sum_rgb2.b)};
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
      const Rgb var_rgb = *tile.rgb_variance_of_mean(x, y);  // known: the luminance's is
      const Rgb rgb = xyz_to_linear_srgb(*mean);
      s.sum_var_rgb = Rgb{s.sum_var_rgb.r + var_rgb.r, s.sum_var_rgb.g + var_rgb.g, s.sum_var_rgb.b + var_rgb.b};
      s.sum_rgb2 = Rgb{s.sum_rgb2.r + rgb.r * rgb.r, s.sum_rgb2.g + rgb.g * rgb.g, s.sum_rgb2.b + rgb.b * rgb.b};
    }
  return s;
}

}  // namespace skyfarm
