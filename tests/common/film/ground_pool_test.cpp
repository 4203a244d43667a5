// Pooled ground pixels (common/film/ground_pool.h): the pool sums the pooled
// rows of every tile, and a pooled tile shows those sums in those rows only.
#include "common/film/ground_pool.h"

#include <gtest/gtest.h>

namespace skyfarm {
namespace {

TEST(GroundPool, SumsThePooledRowsOfEveryTileAndReplacesThemOnly) {
  // Two 4 x 4 tiles stacked (rows 0-3 and 4-7), one batch; rows >= 5 pooled.
  FilmTile top(0, 0, 4, 4, 1), bottom(0, 4, 4, 4, 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 4; ++x) {
      if (y == 7 && x == 3) continue;  // a pixel never traced
      FilmTile& t = y < 4 ? top : bottom;
      t.add_sample(x, y, 0, Xyz{1.0 * x, 1.0 + y, 2.0}, 0.5 * y);
    }
  GroundPool pool(5, 1);
  ASSERT_TRUE(pool.active());
  pool.add(top);  // no pooled rows
  pool.add(bottom);
  double n = 0.0, sum_y = 0.0, sum_y2 = 0.0, sum_l = 0.0;
  for (int y = 5; y < 8; ++y)
    for (int x = 0; x < 4; ++x) {
      if (y == 7 && x == 3) continue;
      n += 1.0;
      sum_y += 1.0 + y;
      sum_y2 += (1.0 + y) * (1.0 + y);
      sum_l += 0.5 * y;
    }
  EXPECT_EQ(pool.sums(0).n, n);
  EXPECT_EQ(pool.sums(0).sum_y, sum_y);
  EXPECT_EQ(pool.sums(0).sum_y2, sum_y2);
  EXPECT_EQ(pool.sums(0).sum_l, sum_l);

  const FilmTile pooled = pool.apply(bottom);
  for (int x = 0; x < 4; ++x) {
    EXPECT_EQ(pooled.sums(x, 4, 0).sum_y, bottom.sums(x, 4, 0).sum_y);  // row 4: not pooled
    EXPECT_EQ(pooled.sums(x, 5, 0).n, n);
    EXPECT_EQ(pooled.sums(x, 6, 0).sum_y, sum_y);
  }
  EXPECT_EQ(pooled.sums(3, 7, 0).n, 0.0);  // untraced stays without samples
  // Every pooled pixel has the pool's mean and the variance of that mean.
  EXPECT_DOUBLE_EQ(pooled.mean_xyz(0, 5)->y, sum_y / n);
  EXPECT_EQ(pooled.luminance_variance_of_mean(1, 6), pooled.luminance_variance_of_mean(2, 5));
  const FilmTile untouched = pool.apply(top);
  EXPECT_EQ(untouched.sums(2, 3, 0).sum_y, top.sums(2, 3, 0).sum_y);
  // shown(): a tile without pooled rows is itself (no copy), one with them the pooled copy.
  std::optional<FilmTile> scratch;
  EXPECT_EQ(&pool.shown(top, &scratch), &top);
  EXPECT_FALSE(scratch.has_value());
  const FilmTile& shown = pool.shown(bottom, &scratch);
  EXPECT_NE(&shown, &bottom);
  EXPECT_EQ(shown.sums(1, 6, 0).n, n);
}

TEST(GroundPool, InactiveBelowZeroAndRejectsOtherBatchCounts) {
  GroundPool none(-1, 1);
  EXPECT_FALSE(none.active());
  FilmTile t(0, 0, 2, 2, 1);
  t.add_sample(0, 0, 0, Xyz{1.0, 1.0, 1.0}, 1.0);
  none.add(t);
  EXPECT_EQ(none.sums(0).n, 0.0);
  EXPECT_EQ(none.apply(t).sums(0, 0, 0).n, 1.0);
  GroundPool two(0, 2);
  EXPECT_THROW(two.add(t), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
