// The image-level estimate of a render's own error: per pixel the
// variance of the luminance mean from the film's sums; per image the
// luminance-weighted relative RMS error against the true image Y,
//     e = sqrt( sum_i var(Y_i) / sum_i Y_i^2 ),
// over the pixels that have an estimate, and the same per linear sRGB channel
//     e_c = sqrt( sum_i var(C_i) / sum_i C_i^2 ),  C = R, G, B
// (the EXR's channels; a colour's noise can be far from its luminance's: the
// blue of a sunset sky is dim next to its red).  The true Y_i are unknown:
// the film's means Y^_i carry the noise, E[Y^_i^2] = Y_i^2 + var(Y^_i), so
//     sum_i Y_i^2 ~ sum_i Y^_i^2 - sum_i var(Y^_i)
// (unbiased), floored at kMinSignalShare of sum_i Y^_i^2.  The plain
// sum_i Y^_i^2 would bound e below about 1 exactly when the image is
// noisiest: a first pass at twilight whose rare large paths make
// sum var / sum Y^2 = 0.92 has e = 3.4, not 0.96 (bench convergence, seed 6:
// true 3.0).  Sums are formed per tile and then
// added in tile order, so every caller (local render, farm) gets the same bits.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "common/film/film_tile.h"

namespace skyfarm {

struct ErrorSums {
  // The floor of the estimated sum Y^2 as a share of the film's (the
  // estimate is then at most 10 sqrt(sum var / sum Y^2)).
  static constexpr double kMinSignalShare = 0.01;
  double sum_var = 0.0;  // sum of var(Y_i) of the mean
  double sum_Y2 = 0.0;   // sum of Y^_i^2, the film's means
  int unknown = 0;       // traced pixels with too few samples for an estimate
  Rgb sum_var_rgb{0.0, 0.0, 0.0};  // per channel, sum of var(C_i) of the mean
  Rgb sum_rgb2{0.0, 0.0, 0.0};     // per channel, sum of C^_i^2
  void add(const ErrorSums& o) {
    sum_var += o.sum_var;
    sum_Y2 += o.sum_Y2;
    unknown += o.unknown;
    sum_var_rgb = Rgb{sum_var_rgb.r + o.sum_var_rgb.r, sum_var_rgb.g + o.sum_var_rgb.g, sum_var_rgb.b + o.sum_var_rgb.b};
    sum_rgb2 = Rgb{sum_rgb2.r + o.sum_rgb2.r, sum_rgb2.g + o.sum_rgb2.g, sum_rgb2.b + o.sum_rgb2.b};
  }
  std::optional<double> relative_rms() const;
  // e_R, e_G, e_B; nullopt when no pixel has an estimate (or the image is
  // black in a channel).
  std::optional<Rgb> relative_rms_rgb() const;
};

// `excluded`: sorted pixel indices y * image_width + x to leave out (the sun
// disk's pixels, render/sun_pixels.h).
ErrorSums error_sums(const FilmTile& tile, const std::vector<std::uint32_t>& excluded = {}, int image_width = 0);

}  // namespace skyfarm
