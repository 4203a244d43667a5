// Tests of the tabulated-function primitive every spectrum and profile uses.
#include "common/core/piecewise_linear.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace skyfarm {
namespace {

TEST(PiecewiseLinear, InterpolatesLinearlyBetweenKnots) {
  PiecewiseLinear f({0.0, 1.0, 3.0}, {0.0, 2.0, -2.0});
  EXPECT_DOUBLE_EQ(f(0.5), 1.0);
  EXPECT_DOUBLE_EQ(f(2.0), 0.0);
  EXPECT_DOUBLE_EQ(f(1.0), 2.0);
}

TEST(PiecewiseLinear, ClampsOrZeroesOutside) {
  PiecewiseLinear clamp({1.0, 2.0}, {5.0, 7.0});
  EXPECT_DOUBLE_EQ(clamp(0.0), 5.0);
  EXPECT_DOUBLE_EQ(clamp(9.0), 7.0);
  PiecewiseLinear zero({1.0, 2.0}, {5.0, 7.0}, PiecewiseLinear::Outside::kZero);
  EXPECT_DOUBLE_EQ(zero(0.0), 0.0);
  EXPECT_DOUBLE_EQ(zero(2.5), 0.0);
  EXPECT_DOUBLE_EQ(zero(1.5), 6.0);
}

TEST(PiecewiseLinear, MaxAndMinOnIntervalAreExact) {
  PiecewiseLinear f({0.0, 1.0, 2.0, 3.0}, {0.0, 4.0, 1.0, 3.0});
  EXPECT_DOUBLE_EQ(f.max_on(0.2, 2.5), 4.0);       // interior knot
  EXPECT_DOUBLE_EQ(f.max_on(1.5, 1.8), f(1.5));    // end point on a falling segment
  EXPECT_DOUBLE_EQ(f.min_on(0.5, 2.9), 1.0);
  EXPECT_DOUBLE_EQ(f.max_on(2.0, 2.0), 1.0);
}

TEST(PiecewiseLinear, IntegralIsExactTrapezoid) {
  PiecewiseLinear f({0.0, 1.0, 3.0}, {0.0, 2.0, 0.0});
  EXPECT_DOUBLE_EQ(f.integral(0.0, 3.0), 3.0);
  EXPECT_DOUBLE_EQ(f.integral(0.5, 1.0), 0.75);
  EXPECT_DOUBLE_EQ(f.integral(-1.0, 0.0), 0.0);  // clamped at value 0
}

TEST(PiecewiseLinear, RejectsBadTables) {
  EXPECT_THROW(PiecewiseLinear({0.0, 0.0}, {1.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(PiecewiseLinear({0.0, 1.0}, {1.0}), std::invalid_argument);
  EXPECT_THROW(PiecewiseLinear({}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
