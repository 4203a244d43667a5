// Progress towards the first of a render's limits (common/render/render_progress.h).
#include "common/render/render_progress.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace skyfarm {
namespace {

TEST(RenderProgress, TheFirstLimitToComeSetsIt) {
  // Samples alone.
  EXPECT_DOUBLE_EQ(render_progress(0.25, 10.0, std::nullopt, std::nullopt, std::nullopt), 0.25);
  // 30 s of a 120 s limit, with a negligible samples share (no sample cap).
  EXPECT_DOUBLE_EQ(render_progress(1e-5, 30.0, 120.0, std::nullopt, std::nullopt), 0.25);
  // An estimate of 2 % for a target of 1 %: a quarter of the samples needed (error ~ 1/sqrt(samples)).
  EXPECT_DOUBLE_EQ(render_progress(1e-5, 30.0, std::nullopt, 0.01, 0.02), 0.25);
  // Both: the larger.
  EXPECT_DOUBLE_EQ(render_progress(1e-5, 60.0, 120.0, 0.01, 0.02), 0.5);
  // Never beyond 1, never NaN.
  EXPECT_DOUBLE_EQ(render_progress(0.1, 500.0, 120.0, std::nullopt, std::nullopt), 1.0);
  EXPECT_DOUBLE_EQ(render_progress(0.1, 1.0, std::nullopt, 0.01, 0.005), 1.0);
  EXPECT_DOUBLE_EQ(render_progress(0.1, 1.0, std::nullopt, 0.01, 0.0), 0.1) << "no estimate yet";
  EXPECT_DOUBLE_EQ(render_progress(std::numeric_limits<double>::quiet_NaN(), 1.0, std::nullopt, std::nullopt,
                                   std::nullopt),
                   0.0);
}

TEST(RenderProgress, RemainingSecondsFollowTheProgressRate) {
  EXPECT_DOUBLE_EQ(*remaining_seconds(0.25, 30.0), 90.0);
  EXPECT_DOUBLE_EQ(*remaining_seconds(1.0, 30.0), 0.0);
  EXPECT_FALSE(remaining_seconds(0.0, 30.0).has_value());
}

}  // namespace
}  // namespace skyfarm
