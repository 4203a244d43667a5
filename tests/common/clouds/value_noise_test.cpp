// Value noise: values in [0, 1) with the uniform's mean, bounded in each cell
// by its corners (and by the coarse cell's lattice points for a finer
// octave), continuous, and pure integer hashing far from the origin.
#include "common/clouds/value_noise.h"

#include <gtest/gtest.h>

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

TEST(ValueNoise, InterpolatesTheCornersAndStaysUnderTheirMaximum) {
  for (int c = 0; c < 50; ++c) {
    const std::int64_t cx = c * 7919 - 3000000, cy = c * 104729, cz = -c;
    EXPECT_EQ(value_noise(3, glm::dvec3(cx, cy, cz)), lattice_value(3, cx, cy, cz));
    for (const int n : {1, 2, 4}) {
      const double bound = value_noise_cell_max(3, cx, cy, cz, n);
      for (int k = 0; k < 300; ++k) {
        const glm::dvec3 f{((k * 7) % 31) / 30.0, ((k * 13) % 29) / 28.0, ((k * 17) % 23) / 22.0};
        const glm::dvec3 x = (glm::dvec3(cx, cy, cz) + f) * static_cast<double>(n);
        ASSERT_LE(value_noise(3, x), bound) << c << " " << n << " " << k;
      }
    }
  }
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
