// Aerosols: Elterman's shape and the Angstrom scaling.
#include "common/atmosphere/aerosol.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/core/integrate.h"

namespace skyfarm {
namespace {

TEST(Aerosol, ShapeIsOneAtGroundAndFollowsElterman) {
  // Elterman (1968) at 340 nm via TUV: beta(1 km)/beta(0) = 0.106/0.240 = 0.441667.
  const auto shape = aerosol::elterman_shape(100000.0);
  EXPECT_DOUBLE_EQ(shape.eval(0.0), 1.0);
  EXPECT_NEAR(shape.eval(1000.0), 0.441667, 1e-6);
  EXPECT_EQ(shape.eval(100001.0), 0.0);
}

TEST(Aerosol, ScaledExtinctionGivesTheRequestedOpticalDepth) {
  for (double top : {100000.0, 20000.0}) {
    const auto shape = aerosol::elterman_shape(top);
    const double k = aerosol::extinction_550_per_m(0.1, top);
    const double tau = integrate_adaptive_simpson([&](double h) { return k * shape.eval(h); }, 0.0, top, 1e-12);
    EXPECT_NEAR(tau, 0.1, 1e-6) << top;
  }
}

TEST(Aerosol, ShapeColumnMatchesEltermanTable) {
  // data/README.md §6: Elterman's column at 340 nm is 0.380 for beta(0) = 0.240 /km,
  // so the shape integrates to 0.380 / 0.240e-3 m = 1583 m (0-50 km; the tail adds ~0).
  const auto shape = aerosol::elterman_shape(100000.0);
  EXPECT_NEAR(shape.column(0.0, 100000.0), 0.380021 / 0.240e-3, 2.0);
}

TEST(Aerosol, AngstromLaw) {
  EXPECT_DOUBLE_EQ(aerosol::angstrom_factor(550.0, 1.3), 1.0);
  EXPECT_NEAR(aerosol::angstrom_factor(1100.0, 1.0), 0.5, 1e-15);
  EXPECT_NEAR(aerosol::angstrom_factor(275.0, 2.0), 4.0, 1e-14);
}

}  // namespace
}  // namespace skyfarm
