// The image-level estimate of a render's own error (DESIGN §6): per pixel the
// variance of the luminance mean from the film's sums; per image the
// luminance-weighted relative RMS error
//     e = sqrt( sum_i var(Y_i) / sum_i Y_i^2 )
// over the pixels that have an estimate.  Sums are formed per tile and then
// added in tile order, so every caller (local render, farm) gets the same bits.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "common/film/film_tile.h"

namespace skyfarm {

struct ErrorSums {
  double sum_var = 0.0;  // sum of var(Y_i) of the mean
  double sum_Y2 = 0.0;   // sum of Y_i^2
  int unknown = 0;       // traced pixels with too few samples for an estimate
  void add(const ErrorSums& o) {
    sum_var += o.sum_var;
    sum_Y2 += o.sum_Y2;
    unknown += o.unknown;
  }
  std::optional<double> relative_rms() const;
};

// `excluded`: sorted pixel indices y * image_width + x to leave out (the sun
// disk's pixels, render/sun_pixels.h).
ErrorSums error_sums(const FilmTile& tile, const std::vector<std::uint32_t>& excluded = {}, int image_width = 0);

}  // namespace skyfarm
