// Pixels that all see the same point, pooled into one estimate.
//
// An observer at 0 m stands on the ground: every direction below the
// horizon meets it at the observer's own feet, after a path of length 0,
// and the ground is Lambertian, so its radiance does not depend on the
// direction.  Every pixel whose whole footprint looks down therefore has
// the same expected value (render_plan.h "pooled_ground_row").  Such pixels
// each trace one sample per pass, and before the image is resolved or its
// error estimated their sums are replaced by the sums of all of them: every
// one shows the mean of all their samples, whose variance is the per-sample
// variance over the total count.  (The image error sqrt(sum var / sum Y^2)
// stays the expected squared error however the pixels are correlated.)
//
// Deterministic: the pool adds the tiles in the order given (the callers'
// tile order), each tile batch by batch, row by row, so the farm and a local
// render pool the same sums into the same bits.
#pragma once
#include <optional>
#include <vector>

#include "common/film/film_tile.h"

namespace skyfarm {

class GroundPool {
 public:
  // Pixels in rows >= first_row (image coordinates) are pooled; first_row < 0: none.
  GroundPool(int first_row, int batches);

  bool active() const { return first_row_ >= 0; }
  // Adds the tile's pooled pixels' sums.
  void add(const FilmTile& tile);
  // The pooled sums of batch b.
  const PixelBatchSums& sums(int batch) const { return sums_[static_cast<std::size_t>(batch)]; }
  // A copy of tile whose pooled pixels hold the pooled sums.
  FilmTile apply(const FilmTile& tile) const;
  // The tile as the image shows it: tile itself when none of its rows is
  // pooled (no copy: the sky's tiles), else apply(tile), kept in *scratch.
  const FilmTile& shown(const FilmTile& tile, std::optional<FilmTile>* scratch) const;

 private:
  bool pooled_rows(const FilmTile& tile, int* y_begin, int* y_end) const;

  int first_row_;
  std::vector<PixelBatchSums> sums_;  // [batch]
};

}  // namespace skyfarm
