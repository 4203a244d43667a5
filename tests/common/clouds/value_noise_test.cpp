// Value noise: values in [0, 1) with the uniform's mean, bounded in each cell
// by its corners (and by the coarse cell's lattice points for a finer
// octave), continuous, and pure integer hashing far from the origin.
#include "common/clouds/value_noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace skyfarm {
namespace {

TEST(ValueNoise, LatticeValuesAreUniformInTheUnitInterval) {
  double sum = 0.0, sum2 = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double v = lattice_value(7, i % 47 - 20, (i / 47) % 53 - 9000000000LL, i / (47 * 53));
    ASSERT_GE(v, 0.0);
    ASSERT_LT(v, 1.0);
    sum += v, sum2 += v * v;
  }
  // The uniform's mean 1/2 and variance 1/12; 5 standard errors.
  EXPECT_NEAR(sum / n, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12.0, 0.002);
  // Permuted coordinates and another seed give other values.
  EXPECT_NE(lattice_value(7, 1, 2, 3), lattice_value(7, 2, 1, 3));
  EXPECT_NE(lattice_value(7, 1, 2, 3), lattice_value(8, 1, 2, 3));
}

// Over a box inside one cell the maximum is at a corner: dense samples of
// the box stay under value_noise_box_max, and the best of them comes close.
TEST(ValueNoise, BoxMaximumBoundsAndIsAttained) {
  for (int c = 0; c < 60; ++c) {
    const glm::dvec3 cell{c * 7919.0 - 3e6, c * 104729.0, -c};
    const glm::dvec3 lo = cell + glm::dvec3(0.25 * (c % 4), 0.25 * ((c / 4) % 4), 0.5 * (c % 2));
    const glm::dvec3 hi = lo + glm::dvec3(0.25, 0.25, 0.5);
    const double bound = value_noise_box_max(3, lo, hi);
    double best = 0.0;
    for (int i = 0; i <= 8; ++i)
      for (int j = 0; j <= 8; ++j)
        for (int k = 0; k <= 8; ++k) {
          const double v = value_noise(3, lo + (hi - lo) * glm::dvec3(i / 8.0, j / 8.0, k / 8.0));
          ASSERT_LE(v, bound) << c;
          best = std::max(best, v);
        }
    EXPECT_NEAR(best, bound, 1e-12) << c;  // the corners are among the samples
  }
  // The whole cell: the largest of its 8 lattice values.
  double corners = 0.0;
  for (int i = 0; i < 8; ++i) corners = std::max(corners, lattice_value(4, 10 + (i & 1), -5 + ((i >> 1) & 1), 2 + (i >> 2)));
  EXPECT_EQ(value_noise_box_max(4, glm::dvec3(10, -5, 2), glm::dvec3(11, -4, 3)), corners);
  EXPECT_EQ(value_noise(3, glm::dvec3(12.0, -7.0, 3.0)), lattice_value(3, 12, -7, 3));
}

TEST(ValueNoise, IsContinuousAcrossCellFaces) {
  for (int i = 0; i < 100; ++i) {
    const glm::dvec3 face{static_cast<double>(i - 50), 0.25 + i * 0.01, -0.7 * i};
    const double below = value_noise(5, face - glm::dvec3(1e-9, 0, 0));
    const double above = value_noise(5, face + glm::dvec3(1e-9, 0, 0));
    EXPECT_NEAR(below, above, 1e-7);
  }
}

}  // namespace
}  // namespace skyfarm
