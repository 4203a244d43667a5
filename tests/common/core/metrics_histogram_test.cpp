// MetricsHistogram: observations land in the first bucket whose bound is >= the
// value (Prometheus' inclusive `le`), the snapshot is cumulative with +Inf ==
// count, the sum is the plain sum, and concurrent observers lose nothing.
#include "common/core/metrics_histogram.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

namespace skyfarm {
namespace {

TEST(MetricsHistogram, CountsAreCumulativeWithInclusiveBounds) {
  const double bounds[] = {1.0, 2.0, 5.0};
  MetricsHistogram h(bounds);
  for (const double v : {0.5, 1.0, 1.5, 2.0, 4.0, 5.0, 7.0, -3.0}) h.observe(v);
  const auto s = h.snapshot();
  ASSERT_EQ(s.upper_bounds, std::vector<double>(std::begin(bounds), std::end(bounds)));
  // <= 1: 0.5, 1.0, -3.0; <= 2: + 1.5, 2.0; <= 5: + 4.0, 5.0; +Inf: + 7.0.
  EXPECT_EQ(s.cumulative, (std::vector<std::uint64_t>{3, 5, 7, 8}));
  EXPECT_EQ(s.count, 8u);
  EXPECT_EQ(s.cumulative.back(), s.count);
  EXPECT_DOUBLE_EQ(s.sum, 0.5 + 1.0 + 1.5 + 2.0 + 4.0 + 5.0 + 7.0 - 3.0);
}

TEST(MetricsHistogram, NanAndInfinityGoToTheInfBucketOnly) {
  const double bounds[] = {1.0};
  MetricsHistogram h(bounds);
  h.observe(std::nan(""));
  h.observe(INFINITY);
  const auto s = h.snapshot();
  EXPECT_EQ(s.cumulative, (std::vector<std::uint64_t>{0, 2}));
  EXPECT_EQ(s.count, 2u);
}

TEST(MetricsHistogram, RefusesBadBounds) {
  EXPECT_THROW(MetricsHistogram(std::span<const double>{}), std::invalid_argument);
  const double unsorted[] = {1.0, 1.0};
  EXPECT_THROW(MetricsHistogram{unsorted}, std::invalid_argument);
  const double infinite[] = {1.0, INFINITY};
  EXPECT_THROW(MetricsHistogram{infinite}, std::invalid_argument);
}

TEST(MetricsHistogram, PresetBoundsAreValid) {
  // The constructor checks them; each preset must pass.
  EXPECT_NO_THROW(MetricsHistogram{kUnitDurationBucketsS});
  EXPECT_NO_THROW(MetricsHistogram{kJobDurationBucketsS});
  EXPECT_NO_THROW(MetricsHistogram{kHttpDurationBucketsS});
}

TEST(MetricsHistogram, ConcurrentObserversLoseNothing) {
  MetricsHistogram h(kHttpDurationBucketsS);
  constexpr int kThreads = 4, kEach = 20000;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&h, t] {
      for (int i = 0; i < kEach; ++i) h.observe(t == 0 ? 0.001 : 100.0);  // first bucket, or +Inf
    });
  for (auto& t : threads) t.join();
  const auto s = h.snapshot();
  EXPECT_EQ(s.count, std::uint64_t{kThreads} * kEach);
  EXPECT_EQ(s.cumulative.front(), std::uint64_t{kEach});
  EXPECT_EQ(s.cumulative.back(), s.count);
  // 0.001 is not exact in binary: the sum is compared within a relative 1e-9.
  EXPECT_NEAR(s.sum, kEach * 0.001 + (kThreads - 1) * kEach * 100.0, 1e-9 * s.sum);
}

}  // namespace
}  // namespace skyfarm
