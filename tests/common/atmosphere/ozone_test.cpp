// Ozone: cross-sections against the values data/README.md quotes for the
// Bogumil v4 table, and the scaled AFGL profile's column.
#include "common/atmosphere/ozone.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/core/constants.h"
#include "common/core/integrate.h"

namespace skyfarm {
namespace {

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

TEST(Ozone, HartleyAndChappuisPeaks) {
  // data/README.md §3: Hartley peak 1.165e-17 cm^2 at 255.5 nm; Chappuis peak
  // 5.36e-21 (293 K) to 5.48e-21 (203 K) cm^2 at 602-603 nm.
  double hartley = 0.0;
  for (double l = 250.0; l <= 260.0; l += 0.01) hartley = std::max(hartley, ozone::cross_section_m2(l, 243.0));
  EXPECT_LT(rel(hartley * 1e4, 1.165e-17), 0.02);
  double chappuis_293 = 0.0, chappuis_203 = 0.0;
  for (double l = 595.0; l <= 610.0; l += 0.01) {
    chappuis_293 = std::max(chappuis_293, ozone::cross_section_m2(l, 293.0));
    chappuis_203 = std::max(chappuis_203, ozone::cross_section_m2(l, 203.0));
  }
  EXPECT_LT(rel(chappuis_293 * 1e4, 5.36e-21), 0.01);
  EXPECT_LT(rel(chappuis_203 * 1e4, 5.48e-21), 0.01);
}

TEST(Ozone, TemperatureInterpolationIsLinearAndClamped) {
  const double l = 320.0;  // Huggins band: strongly temperature dependent
  const double s223 = ozone::cross_section_m2(l, 223.0), s243 = ozone::cross_section_m2(l, 243.0);
  EXPECT_NEAR(ozone::cross_section_m2(l, 233.0), 0.5 * (s223 + s243), 1e-30);
  EXPECT_DOUBLE_EQ(ozone::cross_section_m2(l, 150.0), ozone::cross_section_m2(l, 203.0));
  EXPECT_DOUBLE_EQ(ozone::cross_section_m2(l, 400.0), ozone::cross_section_m2(l, 293.0));
  EXPECT_GT(s243, s223);  // Huggins bands grow with temperature
}

TEST(Ozone, NonNegativeEverywhereAndZeroOutsideTable) {
  for (double l = 200.0; l <= 1100.0; l += 0.05) ASSERT_GE(ozone::cross_section_m2(l, 250.0), 0.0) << l;
  EXPECT_EQ(ozone::cross_section_m2(1100.0, 250.0), 0.0);
}

TEST(Ozone, AfglColumnIs345DobsonUnits) {
  // data/README.md §5: the AFGL U.S.-standard profile holds 345.7 DU (0-120 km).
  EXPECT_LT(rel(ozone::afgl_column_du(120000.0), 345.7), 2e-3);
}

TEST(Ozone, ScaledProfileHoldsTheRequestedColumn) {
  // 300 DU +- 0.1 %, integrated independently by quadrature
  // of the profile's values (not by the table integral used for scaling).
  for (double top : {100000.0, 60000.0}) {
    const auto n = ozone::scaled_profile(300.0, top);
    const double column = integrate_adaptive_simpson([&](double h) { return n.eval(h); }, 0.0, top, 1e-12) +
                          0.0;
    EXPECT_LT(rel(column / kDobsonUnit_per_m2, 300.0), 1e-3) << top;
  }
}

TEST(Ozone, MaxBoundsCrossSection) {
  for (double l0 = 230.0; l0 < 1060.0; l0 += 7.3) {
    const double l1 = l0 + 1.0;
    const double m = ozone::max_cross_section_m2(l0, l1, 210.0, 260.0);
    for (double l = l0; l <= l1; l += 0.01)
      for (double T = 210.0; T <= 260.0; T += 5.0) ASSERT_LE(ozone::cross_section_m2(l, T), m) << l << " " << T;
  }
}

}  // namespace
}  // namespace skyfarm
