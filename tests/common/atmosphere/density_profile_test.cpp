// Density profiles: analytic values, columns and exact maxima.
#include "common/atmosphere/density_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/core/integrate.h"

namespace skyfarm {
namespace {

TEST(DensityProfile, ExponentialValueAndColumn) {
  // Bruneton 2017 functions_test: a vertical column of an exponential layer is
  // H (e^{-h0/H} - e^{-h1/H}).
  const auto p = DensityProfile::exponential(8000.0);
  EXPECT_NEAR(p.eval(8000.0), std::exp(-1.0), 1e-15);
  EXPECT_NEAR(p.column(0.0, 100000.0), 8000.0 * (1.0 - std::exp(-12.5)), 1e-9);
  // Thin slab: dh e^{-h0/H} (1 - x/2 + x^2/6), x = dh/H, with no cancellation.
  const double dh = 1.0 / 1024.0, x = dh / 8000.0;  // dh exact in binary
  EXPECT_NEAR(p.column(1000.0, 1000.0 + dh), dh * std::exp(-0.125) * (1.0 - x / 2.0 + x * x / 6.0), 1e-18);
}

TEST(DensityProfile, BrunetonOzoneTentIntegratesTo15Km) {
  // Bruneton 2017 demo ozone: 0 -> 1 -> 0 over 10-25-40 km as two layers
  // (width 25 km: h/15km - 2/3; then -h/15km + 8/3).  Its column is 15 km.
  const auto p = DensityProfile::layers({{25000.0, 0.0, 0.0, 1.0 / 15000.0, -2.0 / 3.0},
                                         {0.0, 0.0, 0.0, -1.0 / 15000.0, 8.0 / 3.0}});
  EXPECT_NEAR(p.eval(25000.0), 1.0, 1e-12);
  EXPECT_NEAR(p.eval(5000.0), 0.0, 1e-12);
  EXPECT_NEAR(p.column(0.0, 60000.0), 15000.0, 1e-3);
  EXPECT_NEAR(p.max_on(0.0, 60000.0), 1.0, 1e-12);
  EXPECT_NEAR(p.max_on(30000.0, 35000.0), p.eval(30000.0), 1e-12);
}

TEST(DensityProfile, TableIsZeroOutside) {
  const auto p = DensityProfile::table(PiecewiseLinear({1000.0, 2000.0}, {1.0, 3.0}));
  EXPECT_EQ(p.eval(500.0), 0.0);
  EXPECT_EQ(p.eval(2500.0), 0.0);
  EXPECT_DOUBLE_EQ(p.eval(1500.0), 2.0);
  EXPECT_DOUBLE_EQ(p.column(0.0, 5000.0), 2000.0);
}

// max_on must bound eval everywhere in the interval, for every kind,
// including a layer whose interior extremum is a bump (exp + linear).
TEST(DensityProfile, MaxOnBoundsEvalEverywhere) {
  const DensityProfile profiles[] = {
      DensityProfile::exponential(1200.0),
      DensityProfile::us76_air(),
      DensityProfile::table(PiecewiseLinear({0.0, 3000.0, 7000.0, 9000.0}, {0.2, 1.0, 0.1, 0.5})),
      DensityProfile::layers({{5000.0, -1.0, -1.0 / 2000.0, 0.0, 1.0}, {0.0, 0.5, -1.0 / 3000.0, 2e-5, 0.0}}),
  };
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (const auto& p : profiles) {
    for (int i = 0; i < 2000; ++i) {
      const double h0 = 20000.0 * U(rng), h1 = h0 + 3000.0 * U(rng);
      const double m = p.max_on(h0, h1);
      for (int k = 0; k <= 50; ++k) {
        const double h = h0 + (h1 - h0) * k / 50.0;
        ASSERT_LE(p.eval(h), m * (1.0 + 1e-12)) << "h0=" << h0 << " h1=" << h1 << " h=" << h;
      }
    }
  }
}

TEST(DensityProfile, LayersColumnMatchesQuadrature) {
  const auto p = DensityProfile::layers({{5000.0, -1.0, -1.0 / 2000.0, 0.0, 1.0}, {0.0, 0.5, -1.0 / 3000.0, 0.0, 0.0}});
  const double q = integrate_adaptive_simpson([&](double h) { return p.eval(h); }, 0.0, 5000.0, 1e-12) +
                   integrate_adaptive_simpson([&](double h) { return p.eval(h); }, 5000.0, 50000.0, 1e-12);
  EXPECT_NEAR(p.column(0.0, 50000.0), q, 1e-6 * q);
}

}  // namespace
}  // namespace skyfarm
