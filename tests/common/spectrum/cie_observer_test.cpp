// The CIE 1931 2° observer carries the values its source states
// (data/README.md §1 "cie1931_2deg_xyz.csv"; CIE 018:2004 1-nm table).
#include "common/spectrum/cie_observer.h"

#include <gtest/gtest.h>

namespace skyfarm {
namespace {

// data/README.md: "ybar = 1.000000 at 555 nm" (the photopic peak, CIE 018:2004).
TEST(CieObserver, YbarPeaksAtOneAt555nm) {
  EXPECT_DOUBLE_EQ(cie1931_ybar(555.0), 1.0);
  const CieObserver& o = cie1931_observer();
  EXPECT_DOUBLE_EQ(o.ybar.max_on(360.0, 830.0), 1.0);
  EXPECT_LT(cie1931_ybar(554.0), 1.0);
  EXPECT_LT(cie1931_ybar(556.0), 1.0);
}

// data/README.md: Σx̄, Σȳ, Σz̄ on the 1 nm grid = 106.866 / 106.857 / 106.892.
// The table's exact sums are 106.865469 / 106.856917 / 106.892251: Σx̄ rounds to
// 106.865, so the README's "106.866" is off in the last digit (double rounding
// via 106.8655); x̄ is checked to 1e-3, ȳ and z̄ to 5e-4.
TEST(CieObserver, SumsOnOneNanometreGridMatchPublished) {
  double sx = 0.0, sy = 0.0, sz = 0.0;
  for (int l = 360; l <= 830; ++l) {
    const Xyz c = cie1931_cmf(l);
    sx += c.x;
    sy += c.y;
    sz += c.z;
  }
  EXPECT_NEAR(sx, 106.866, 1e-3);
  EXPECT_NEAR(sy, 106.857, 5e-4);
  EXPECT_NEAR(sz, 106.892, 5e-4);
  // pbrt-v4 src/pbrt/util/spectrum.h: CIE_Y_integral = 106.856895, the 1 nm sum
  // of pbrt's own copy of the table, which differs from CIE 018:2004 by 2.2e-5.
  EXPECT_NEAR(sy, 106.856895, 3e-5);
}

// ∫ȳ dλ = trapezoid on the 1 nm grid = Σȳ − (ȳ(360) + ȳ(830))/2 ≈ 106.857.
TEST(CieObserver, YbarIntegralIsTrapezoidOfTable) {
  double sum = 0.0;
  for (int l = 360; l <= 830; ++l) sum += cie1931_ybar(l);
  const double ends = 0.5 * (cie1931_ybar(360.0) + cie1931_ybar(830.0));
  EXPECT_NEAR(cie1931_ybar_integral_nm(), sum - ends, 1e-10);
  EXPECT_NEAR(cie1931_ybar_integral_nm(), 106.857, 5e-4);
}

TEST(CieObserver, ZeroOutsideTableAndLinearInside) {
  EXPECT_EQ(cie1931_ybar(359.9), 0.0);
  EXPECT_EQ(cie1931_ybar(830.1), 0.0);
  EXPECT_GT(cie1931_ybar(360.0), 0.0);
  // Linear between knots: ȳ(554.5) = (ȳ(554) + ȳ(555))/2.
  EXPECT_DOUBLE_EQ(cie1931_ybar(554.5), 0.5 * (cie1931_ybar(554.0) + cie1931_ybar(555.0)));
  // Table values (CIE 018:2004): x̄, z̄ at 555 nm = 0.5120501, 0.005749999.
  const Xyz c = cie1931_cmf(555.0);
  EXPECT_DOUBLE_EQ(c.x, 0.5120501);
  EXPECT_DOUBLE_EQ(c.z, 0.005749999);
}

}  // namespace
}  // namespace skyfarm
