// The deterministic sampler: a pure function of its keys, uniform, and
// sensitive to every key.
#include "common/sampling/sampler.h"

#include <gtest/gtest.h>

#include <set>

#include "tests/support/chi2.h"

namespace skyfarm {
namespace {

TEST(Sampler, IsAPureFunctionOfItsKeys) {
  Sampler a(1, 2, 3), b(1, 2, 3);
  for (int i = 0; i < 100; ++i) ASSERT_EQ(a.next(), b.next());
  EXPECT_EQ(Sampler(1, 2, 3).get(7), Sampler(1, 2, 3).get(7));
}

TEST(Sampler, EveryKeyChangesTheStream) {
  const double base = Sampler(1, 2, 3).get(4);
  EXPECT_NE(base, Sampler(2, 2, 3).get(4));
  EXPECT_NE(base, Sampler(1, 3, 3).get(4));
  EXPECT_NE(base, Sampler(1, 2, 4).get(4));
  EXPECT_NE(base, Sampler(1, 2, 3).get(5));
  // Swapped keys differ too.
  EXPECT_NE(Sampler(1, 2, 3).get(4), Sampler(1, 3, 2).get(4));
}

TEST(Sampler, ValuesAreInUnitIntervalAndUniform) {
  std::vector<double> samples;
  for (std::uint64_t pixel = 0; pixel < 200; ++pixel)
    for (std::uint64_t s = 0; s < 100; ++s)
      for (std::uint64_t d = 0; d < 5; ++d) {
        const double u = Sampler(42, pixel, s).get(d);
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        samples.push_back(u);
      }
  const auto r = testing::chi2_test_1d([](double) { return 1.0; }, samples, 0.0, 1.0, 100);
  EXPECT_GT(r.p_value, 0.01) << r.detail;
}

TEST(Sampler, ConsecutiveDimensionsAreUncorrelated) {
  // Pairs (u_d, u_{d+1}) binned on a 10 x 10 grid: uniform (chi-square via the
  // 1-D harness on the cell index).
  std::vector<double> cells;
  for (std::uint64_t s = 0; s < 100000; ++s) {
    Sampler sampler(7, 0, s);
    const double a = sampler.next(), b = sampler.next();
    cells.push_back((static_cast<int>(a * 10) * 10 + static_cast<int>(b * 10) + 0.5) / 100.0);
  }
  const auto r = testing::chi2_test_1d([](double) { return 1.0; }, cells, 0.0, 1.0, 100);
  EXPECT_GT(r.p_value, 0.01) << r.detail;
}

}  // namespace
}  // namespace skyfarm
