// The layer types' height profiles: in [0, 1], zero outside the layer, the
// closed-form integral against the midpoint rule, and max_over (what the
// majorants use) against dense sampling.
#include "common/clouds/cloud_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

namespace skyfarm {
namespace {

constexpr CloudType kTypes[] = {CloudType::kCumulus, CloudType::kStratocumulus, CloudType::kStratus,
                                CloudType::kCirrus, CloudType::kCustom};

TEST(CloudProfile, IsZeroOutsideAndUnitOnThePlateau) {
  for (const CloudType type : kTypes) {
    const CloudProfile p = CloudProfile::for_type(type);
    EXPECT_EQ(p(-0.1), 0.0);
    EXPECT_EQ(p(0.0), 0.0);
    EXPECT_EQ(p(1.0), 0.0);
    EXPECT_EQ(p(1.5), 0.0);
    EXPECT_EQ(p(0.5 * (p.rise_end() + p.fall_begin())), 1.0);
    for (int i = 0; i <= 1000; ++i) {
      const double v = p(i / 1000.0);
      EXPECT_GE(v, 0.0);
      EXPECT_LE(v, 1.0);
    }
  }
}

// The midpoint rule with 1e5 steps: the error is below 1e-8 for these C1 cubics.
TEST(CloudProfile, IntegralMatchesTheMidpointRule) {
  for (const CloudType type : kTypes) {
    const CloudProfile p = CloudProfile::for_type(type);
    const int n = 100000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += p((i + 0.5) / n);
    EXPECT_NEAR(sum / n, p.integral(), 1e-8) << cloud_type_name(type);
  }
}

TEST(CloudProfile, MaxOverBoundsAndAttainsTheDenseMaximum) {
  for (const CloudType type : kTypes) {
    const CloudProfile p = CloudProfile::for_type(type);
    for (int i = 0; i < 200; ++i) {
      const double x0 = -0.1 + 1.2 * ((i * 37) % 200) / 200.0, x1 = x0 + 0.3 * ((i * 11) % 17) / 17.0;
      double dense = 0.0;
      for (int k = 0; k <= 2000; ++k) dense = std::max(dense, p(x0 + (x1 - x0) * k / 2000.0));
      const double bound = p.max_over(x0, x1);
      EXPECT_GE(bound, dense) << x0 << " " << x1;
      EXPECT_NEAR(bound, dense, 1e-12) << x0 << " " << x1;  // the maximum is at a sample (an end or the plateau)
    }
  }
}

TEST(CloudProfile, RejectsEdgesOutOfOrder) {
  EXPECT_THROW(CloudProfile(0.0, 0.5), std::invalid_argument);
  EXPECT_THROW(CloudProfile(0.6, 0.5), std::invalid_argument);
  EXPECT_THROW(CloudProfile(0.2, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
