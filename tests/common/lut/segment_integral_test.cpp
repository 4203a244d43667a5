// The per-step closed forms of the ray marches (common/lut/segment_integral.h)
// against their analytic values, including the limits where the textbook
// quotient (1 - exp(-sigma_t dt)) / sigma_t is 0/0 or cancels.
#include "common/lut/segment_integral.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace skyfarm {
namespace {

using lut::in_scattering_integral;
using lut::T;
using lut::T_and_in_scattering_integral;

// Exact: int_0^dt exp(-s t) dt = (1 - exp(-s dt)) / s; for s dt << 1 its
// series dt (1 - x/2 + x^2/6 - x^3/24), x = s dt (to 1e-15 relative here).
TEST(LutSegmentIntegral, MatchesAnalyticValuesAcrossScales) {
  struct Case {
    double sigma_t, dt, T, integral;
  };
  const Case cases[] = {
      {0.0, 1e5, 1.0, 1e5},                                                          // empty layer: the step's length
      {1e-30, 1e5, 1.0, 1e5 * (1.0 - 0.5e-25)},                                      // underflowed coefficient
      {1e-12, 1e3, 1.0 - 1e-9, 1e3 * (1.0 - 0.5e-9)},                                // x = 1e-9
      {1e-5, 1.0, std::exp(-1e-5), 1.0 - 0.5e-5 + 1e-10 / 6},                        // x = 1e-5, below the series cut
      {1e-5, 10.0, std::exp(-1e-4), 10.0 * (1.0 - 0.5e-4 + 1e-8 / 6 - 1e-12 / 24)},  // at the cut
      {1e-5, 1e5, std::exp(-1.0), (1.0 - std::exp(-1.0)) / 1e-5},                    // x = 1
      {1e-3, 2e4, std::exp(-20.0), (1.0 - std::exp(-20.0)) / 1e-3},
      {1e3, 1e5, 0.0, 1e-3},  // opaque: exp(-1e8) underflows to 0, integral 1/sigma_t
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(::testing::Message() << "sigma_t " << c.sigma_t << " dt " << c.dt);
    EXPECT_NEAR(T(c.sigma_t, c.dt), c.T, 1e-15);
    EXPECT_NEAR(in_scattering_integral(c.sigma_t, c.dt), c.integral, 1e-13 * c.integral);
    double integral = -1.0;
    EXPECT_NEAR(T_and_in_scattering_integral(c.sigma_t, c.dt, &integral), c.T, 1e-15);
    EXPECT_NEAR(integral, c.integral, 1e-11 * c.integral);  // 1 - exp(-x) for x >= 1e-4: <= eps/x
  }
}

// Continuity across the series cut x = 1e-4 (no jump between the branches).
TEST(LutSegmentIntegral, ContinuousAcrossTheSeriesCut) {
  const double dt = 1000.0;
  for (double x : {1e-4 * (1.0 - 1e-12), 1e-4, 1e-4 * (1.0 + 1e-12)}) {
    const double exact = dt * (1.0 - x / 2.0 + x * x / 6.0 - x * x * x / 24.0);
    EXPECT_NEAR(in_scattering_integral(x / dt, dt), exact, 5e-14 * exact);  // series: next term x^3/24
    double integral;
    T_and_in_scattering_integral(x / dt, dt, &integral);
    EXPECT_NEAR(integral, exact, 3e-12 * exact);
  }
}

// Never NaN, never negative, monotone in dt; negative inputs (round-off of
// an interpolated table) are treated as 0.
TEST(LutSegmentIntegral, FiniteNonNegativeAndClampedForBadInputs) {
  const double big = std::numeric_limits<double>::max();
  for (double s : {0.0, 1e-300, 1e-30, 1.0, 1e300, big, -1e-20})
    for (double dt : {0.0, 1e-300, 1.0, 1e7, 1e300, -5.0}) {
      double integral = -1.0;
      const double t = T_and_in_scattering_integral(s, dt, &integral);
      EXPECT_TRUE(std::isfinite(t) && t >= 0.0 && t <= 1.0) << s << " " << dt;
      EXPECT_TRUE(std::isfinite(integral) && integral >= 0.0) << s << " " << dt;
      EXPECT_TRUE(std::isfinite(in_scattering_integral(s, dt))) << s << " " << dt;
      EXPECT_LE(in_scattering_integral(s, dt), std::max(0.0, dt)) << s << " " << dt;
    }
  EXPECT_EQ(T(-1.0, 5.0), 1.0);
  EXPECT_EQ(in_scattering_integral(-1.0, 5.0), 5.0);
  EXPECT_EQ(in_scattering_integral(1.0, -5.0), 0.0);
  EXPECT_LT(in_scattering_integral(1e-4, 10.0), in_scattering_integral(1e-4, 20.0));
}

// The single-precision variant against the analytic values in double:
// relative error < 3e-6 everywhere (the quotient's cancellation eps_f/x is at
// most 2e-6 just above the series cut x = 0.03), continuous across the cut,
// and finite and non-negative for bad inputs.
TEST(LutSegmentIntegral, SinglePrecisionVariantMatchesTheAnalyticValues) {
  double worst = 0.0;
  for (double x = 1e-9; x < 80.0; x *= 1.01) {
    for (double dt : {1.0, 1000.0, 64000.0}) {
      const float s = static_cast<float>(x / dt), d = static_cast<float>(dt);
      const double xs = s * d;  // x as rounded in single precision, as the function forms it
      const double exact_T = std::exp(-xs), exact_integral = static_cast<double>(d) * -std::expm1(-xs) / xs;
      float integral = -1.0f;
      const float t = lut::T_and_in_scattering_integral_f(s, d, &integral);
      worst = std::max(worst, std::abs(integral - exact_integral) / exact_integral);
      EXPECT_NEAR(t, exact_T, 3e-7 * exact_T) << x;
    }
  }
  EXPECT_LT(worst, 3e-6);
  for (float s : {0.0f, 1e-40f, 1.0f, 3e38f, -1e-20f})
    for (float dt : {0.0f, 1.0f, 1e7f, -5.0f}) {
      float integral = -1.0f;
      const float t = lut::T_and_in_scattering_integral_f(s, dt, &integral);
      EXPECT_TRUE(std::isfinite(t) && t >= 0.0f && t <= 1.0f) << s << " " << dt;
      EXPECT_TRUE(std::isfinite(integral) && integral >= 0.0f && integral <= std::max(0.0f, dt)) << s << " " << dt;
    }
}

}  // namespace
}  // namespace skyfarm
