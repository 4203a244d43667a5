#include "common/film/ground_pool.h"

#include <algorithm>
#include <stdexcept>

namespace skyfarm {

namespace {
void add_to(PixelBatchSums* a, const PixelBatchSums& b) {
  a->n += b.n;
  a->sum_x += b.sum_x;
  a->sum_y += b.sum_y;
  a->sum_z += b.sum_z;
  a->sum_y2 += b.sum_y2;
  a->sum_l += b.sum_l;
  a->sum_r2 += b.sum_r2;
  a->sum_g2 += b.sum_g2;
  a->sum_b2 += b.sum_b2;
}
}  // namespace

GroundPool::GroundPool(int first_row, int batches)
    : first_row_(first_row), sums_(static_cast<std::size_t>(std::max(batches, 0))) {}

bool GroundPool::pooled_rows(const FilmTile& tile, int* y_begin, int* y_end) const {
  if (!active()) return false;
  *y_begin = std::max(first_row_, tile.y0());
  *y_end = tile.y0() + tile.height();
  return *y_begin < *y_end;
}

void GroundPool::add(const FilmTile& tile) {
  if (tile.batches() != static_cast<int>(sums_.size()))
    throw std::invalid_argument("ground pool: a tile of " + std::to_string(tile.batches()) + " batches, the pool has " +
                                std::to_string(sums_.size()));
  int y0 = 0, y1 = 0;
  if (!pooled_rows(tile, &y0, &y1)) return;
  for (int b = 0; b < tile.batches(); ++b)
    for (int y = y0; y < y1; ++y)
      for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x)
        add_to(&sums_[static_cast<std::size_t>(b)], tile.sums(x, y, b));
}

FilmTile GroundPool::apply(const FilmTile& tile) const {
  FilmTile out = tile;
  int y0 = 0, y1 = 0;
  if (!pooled_rows(tile, &y0, &y1)) return out;
  for (int b = 0; b < tile.batches(); ++b)
    for (int y = y0; y < y1; ++y)
      for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x)
        if (tile.sums(x, y, b).n > 0.0) out.set_sums(x, y, b, sums_[static_cast<std::size_t>(b)]);
  return out;
}

const FilmTile& GroundPool::shown(const FilmTile& tile, std::optional<FilmTile>* scratch) const {
  int y0 = 0, y1 = 0;
  if (!pooled_rows(tile, &y0, &y1)) return tile;
  return scratch->emplace(apply(tile));
}

}  // namespace skyfarm
