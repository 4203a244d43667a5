// A set of tables on one uniform grid gives, column by column, exactly what a
// table of that one function would (the medium's bits depend on it): the
// knot values, linear interpolation in between, the end values outside; one
// located position serves every column; min_on is the exact minimum.
#include "common/render/uniform_table_set.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace skyfarm {
namespace {

// A single table of f on the grid, written out as the medium's tables were
// before they were grouped: u = (x - x0) / step, v_i + u (v_{i+1} - v_i).
class SingleTable {
 public:
  SingleTable(const std::function<double(double)>& f, double x0, double x1, int n)
      : x0_(x0), inv_step_((n - 1) / (x1 - x0)), v_(static_cast<std::size_t>(n)) {
    for (int i = 0; i < n; ++i) v_[static_cast<std::size_t>(i)] = f((i + 1 == n) ? x1 : x0 + (x1 - x0) * i / (n - 1));
  }
  double eval(double x) const {
    double u = (x - x0_) * inv_step_;
    if (!(u > 0.0)) return v_.front();
    if (u >= static_cast<double>(v_.size() - 1)) return v_.back();
    const auto i = static_cast<std::size_t>(u);
    u -= static_cast<double>(i);
    return v_[i] + u * (v_[i + 1] - v_[i]);
  }

 private:
  double x0_, inv_step_;
  std::vector<double> v_;
};

const std::vector<std::function<double(double)>>& functions() {
  static const std::vector<std::function<double(double)>> f = {
      [](double x) { return std::exp(-x / 8000.0); },
      [](double x) { return 1e-6 * std::sin(x / 3000.0) + 2e-6; },
      [](double) { return 0.0; },
      [](double x) { return 200.0 + 1e-3 * x; },
  };
  return f;
}

TEST(UniformTableSet, EachColumnIsBitForBitASingleTable) {
  const double x0 = 0.0, x1 = 100000.0;
  const int n = 4001;
  const UniformTableSet set(x0, x1, n, functions());
  ASSERT_EQ(set.columns(), functions().size());
  std::vector<SingleTable> singles;
  for (const auto& f : functions()) singles.emplace_back(f, x0, x1, n);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> x_of(-1000.0, 101000.0);
  for (int trial = 0; trial < 2000; ++trial) {
    // Random points, inside and outside, and exact knots.
    const double x = (trial % 4 == 0) ? x0 + (x1 - x0) * (trial / 4) / (n - 1) : x_of(rng);
    const UniformTableSet::Position at = set.locate(x);
    for (std::size_t c = 0; c < set.columns(); ++c) {
      const double want = singles[c].eval(x);
      EXPECT_EQ(set.eval(at, c), want) << "column " << c << " at x = " << x;
      EXPECT_EQ(set.eval(x, c), want);
    }
  }
}

TEST(UniformTableSet, HoldsTheEndValuesOutsideAndInterpolatesBetweenKnots) {
  const UniformTableSet set(10.0, 20.0, 3, {[](double x) { return x * x; }});
  EXPECT_EQ(set.eval(5.0, 0), 100.0);
  EXPECT_EQ(set.eval(10.0, 0), 100.0);
  EXPECT_EQ(set.eval(15.0, 0), 225.0);
  EXPECT_EQ(set.eval(20.0, 0), 400.0);
  EXPECT_EQ(set.eval(1e9, 0), 400.0);
  EXPECT_DOUBLE_EQ(set.eval(12.5, 0), 162.5);  // halfway between 100 and 225
  EXPECT_EQ(set.eval(std::nan(""), 0), 100.0);
}

TEST(UniformTableSet, OneKnotIsAConstant) {
  const UniformTableSet set(0.0, 0.0, 1, {[](double) { return 3.0; }, [](double) { return -1.0; }});
  EXPECT_EQ(set.eval(-5.0, 0), 3.0);
  EXPECT_EQ(set.eval(7.0, 1), -1.0);
}

TEST(UniformTableSet, MinOnIsTheExactMinimumOfTheInterpolant) {
  const double x0 = 0.0, x1 = 1000.0;
  const UniformTableSet set(x0, x1, 51, functions());
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> x_of(-50.0, 1050.0);
  for (int trial = 0; trial < 200; ++trial) {
    double a = x_of(rng), b = x_of(rng);
    if (b < a) std::swap(a, b);
    for (std::size_t c = 0; c < set.columns(); ++c) {
      const double m = set.min_on(c, a, b);
      // The minimum is attained (at an end or a knot) and nothing is lower.
      double sampled = std::min(set.eval(a, c), set.eval(b, c));
      for (int k = 0; k <= 500; ++k) {
        const double v = set.eval(a + (b - a) * k / 500.0, c);
        EXPECT_GE(v, m - 1e-15 * std::abs(m));
        sampled = std::min(sampled, v);
      }
      for (int i = 0; i < 51; ++i) {
        const double knot = x0 + (x1 - x0) * i / 50.0;
        if (knot >= a && knot <= b) sampled = std::min(sampled, set.eval(knot, c));
      }
      EXPECT_NEAR(m, sampled, 1e-12 * std::abs(sampled)) << "column " << c << " on [" << a << ", " << b << "]";
    }
  }
}

}  // namespace
}  // namespace skyfarm
