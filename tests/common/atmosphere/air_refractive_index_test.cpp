// Ciddor's (1996) refractive index of dry air against a published value and
// against the independent modified Edlén equation of Birch & Downs (1993,
// 1994) as NIST's Engineering Metrology Toolbox states it.
#include "common/atmosphere/air_refractive_index.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/atmosphere/us76.h"

namespace skyfarm {
namespace {

// Birch & Downs (1993, 1994) update of Edlén (1966), dry air, t in C, p in Pa
// (NIST EMT documentation, Appendix A-IV):
//   1e8 (n - 1)_s = 8342.54 + 2406147 / (130 - s^2) + 15998 / (38.9 - s^2)
//   (n - 1)_tp = p (n - 1)_s / 96095.43 x (1 + 1e-8 (0.601 - 0.00972 t) p) / (1 + 0.003661 t)
double edlen_refractivity(double lambda_nm, double p, double t) {
  const double s2 = 1.0 / ((lambda_nm * 1e-3) * (lambda_nm * 1e-3));
  const double ns = 1e-8 * (8342.54 + 2406147.0 / (130.0 - s2) + 15998.0 / (38.9 - s2));
  return p * ns / 96095.43 * (1.0 + 1e-8 * (0.601 - 0.00972 * t) * p) / (1.0 + 0.003661 * t);
}

TEST(AirRefractiveIndex, StandardAirMatchesPublishedCiddorValue) {
  // ADAS (adas.ac.uk) documents vacuum2air(5300 A, method='ciddor1996') =
  // 5298.525674870389 A for Ciddor's standard air: n = 5300 / 5298.525674870389.
  EXPECT_NEAR(1.0 + air::standard_refractivity(530.0), 5300.0 / 5298.525674870389, 1e-10);
  // At 15 C and 101 325 Pa the density ratio is 1: refractivity() reduces to eq. 1.
  EXPECT_NEAR(air::refractivity(530.0, 101325.0, 288.15), air::standard_refractivity(530.0), 1e-15);
}

TEST(AirRefractiveIndex, SeaLevelUs76At550nm) {
  // US76 sea level is Ciddor's standard state (15 C, 101 325 Pa): n - 1 = 2.7784e-4
  // at 550 nm (the usual ~2.77e-4; Bucholtz's Peck & Reeder value is 2.7781e-4).
  EXPECT_NEAR(air::us76_refractivity(550.0, 0.0), 2.7784e-4, 1e-8);
}

TEST(AirRefractiveIndex, AgreesWithModifiedEdlenWithinNistStatedDifference) {
  // NIST EMT (section VII): for dry air the two equations agree to about 1e-8
  // over ordinary conditions; CO2 450 ppm is assumed by both here.
  for (double lambda : {400.0, 500.0, 633.0, 700.0})
    for (double t : {0.0, 15.0, 30.0})
      for (double p : {80000.0, 101325.0, 110000.0}) {
        SCOPED_TRACE(testing::Message() << lambda << " nm, " << t << " C, " << p << " Pa");
        EXPECT_NEAR(air::refractivity(lambda, p, t + 273.15), edlen_refractivity(lambda, p, t), 2e-8);
      }
  // The He-Ne line at 20 C, 101 325 Pa, dry: both give n = 1.0002718 (to 1e-7).
  EXPECT_NEAR(air::refractivity(633.0, 101325.0, 293.15), 2.718e-4, 1e-7);
}

TEST(AirRefractiveIndex, ScalesWithDensityAndFallsWithAltitude) {
  // Ideal gas to ~4e-4 (compressibility): (n - 1) / density nearly constant with altitude.
  const double at0 = air::us76_refractivity(550.0, 0.0) / us76::number_density_per_m3(0.0);
  for (double h : {5000.0, 11000.0, 30000.0, 80000.0})
    EXPECT_NEAR(air::us76_refractivity(550.0, h) / us76::number_density_per_m3(h) / at0, 1.0, 5e-4) << h;
  // Dispersion: monotone decreasing with wavelength over the visible.
  double previous = 1.0;
  for (double l = 380.0; l <= 780.0; l += 10.0) {
    EXPECT_LT(air::standard_refractivity(l), previous);
    previous = air::standard_refractivity(l);
  }
}

}  // namespace
}  // namespace skyfarm
