// The baked detail noise: in [0, 1], periodic (exactly, by integer wrapping,
// even 1e7 periods away), the same table for the same seed.
#include "common/clouds/tiled_worley_noise.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace skyfarm {
namespace {

TEST(TiledWorleyNoise, IsPeriodicBoundedAndSeeded) {
  const TiledWorleyNoise a(1), b(1), c(2);
  constexpr double kPeriod = TiledWorleyNoise::kSize;
  int differ = 0;
  double lo = 1.0, hi = 0.0;
  for (int i = 0; i < 2000; ++i) {
    // Multiples of 1/64: the shifted points' fractions are exact.
    const glm::dvec3 x{(i % 37) * 55 / 64.0, (i % 41) * 73 / 64.0, (i % 43) * 39 / 64.0};
    const double v = a.lookup(x);
    ASSERT_GE(v, 0.0);
    ASSERT_LE(v, 1.0);
    lo = std::min(lo, v), hi = std::max(hi, v);
    // Shifts by whole periods of exactly representable size: the same bits.
    ASSERT_EQ(v, a.lookup(x + glm::dvec3(kPeriod, -2.0 * kPeriod, 0.0)));
    ASSERT_EQ(v, a.lookup(x + glm::dvec3(0.0, 0.0, kPeriod * 1048576.0)));
    ASSERT_EQ(v, b.lookup(x));
    differ += v != c.lookup(x);
  }
  EXPECT_GT(differ, 1500);
  // Worley F1 spans from the feature points (near 0) to the gaps.
  EXPECT_LT(lo, 0.25);
  EXPECT_GT(hi, 0.5);
}

}  // namespace
}  // namespace skyfarm
