// Rayleigh scattering against Bucholtz (1995), Appl. Opt. 34, 2765: the
// cross-section formula (eq. 8) and the published Table 3 fits of the
// cross-section and of the vertical optical depth of the U.S. Standard
// Atmosphere (sigma = A lambda^-(B + C lambda + D / lambda), lambda in um;
// values in data/rayleigh_bucholtz1995.csv).
#include "common/atmosphere/rayleigh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/atmosphere/density_profile.h"
#include "common/data/csv_table.h"

namespace skyfarm {
namespace {

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

// Bucholtz Table 3 fit of the cross-section, cm^2.
double bucholtz_fit_sigma_cm2(double lambda_nm) {
  const double l = lambda_nm * 1e-3;
  if (l <= 0.5) return 3.01577e-28 * std::pow(l, -(3.55212 + 1.35579 * l + 0.11563 / l));
  return 4.01061e-28 * std::pow(l, -(3.99668 + 1.10298e-3 * l + 2.71393e-2 / l));
}

TEST(Rayleigh, CrossSectionAt550nm) {
  // Bucholtz eq. 8 at 550 nm: 4.509e-27 cm^2 (data/README.md; the fit gives 4.507e-27).
  const double sigma_cm2 = rayleigh::cross_section_m2(550.0) * 1e4;
  EXPECT_LT(rel(sigma_cm2, 4.509e-27), 1e-3);
}

TEST(Rayleigh, CrossSectionMatchesBucholtzFitFrom250To1000nm) {
  // The Table 3 fit reproduces eq. 8 to about 0.3 % (Bucholtz §3).
  for (double l = 250.0; l <= 1000.0; l += 5.0) EXPECT_LT(rel(rayleigh::cross_section_m2(l) * 1e4, bucholtz_fit_sigma_cm2(l)), 4e-3) << l;
}

TEST(Rayleigh, KingFactorAndDepolarisationTable) {
  // Bucholtz Table 1: rho_n(550 nm) = 0.02842, F_k = 1.04899.
  EXPECT_NEAR(rayleigh::depolarization(550.0), 0.02842, 1e-6);
  EXPECT_NEAR(rayleigh::king_factor(550.0), 1.04899, 1e-5);
  EXPECT_NEAR(rayleigh::phase_gamma(550.0), 0.02842 / (2.0 - 0.02842), 1e-12);
  // Beyond the table: 2.730 %.
  EXPECT_NEAR(rayleigh::depolarization(1500.0), 0.02730, 1e-9);
}

TEST(Rayleigh, VerticalOpticalDepthOfUs76MatchesBucholtz) {
  // Bucholtz Table 3 fit of tau for the U.S. Standard Atmosphere, surface to top:
  // tau = A lambda^-(B + C lambda + D / lambda), A = 6.50362e-3 (<= 0.5 um) / 8.64627e-3.
  // Published digits: tau(400) = 0.3610, tau(550) = 0.09716, tau(700) = 0.03648.
  // Tolerance 1 %: the fit itself is good to ~0.5 % and his air column differs
  // slightly from the US76 column integrated to 100 km here.
  const auto air = DensityProfile::us76_air();
  const double column_per_m2 = air.column(0.0, 100000.0);
  const struct { double lambda, tau; } published[] = {{400.0, 0.3610}, {550.0, 0.09716}, {700.0, 0.03648}};
  for (const auto& p : published) {
    const double tau = rayleigh::cross_section_m2(p.lambda) * column_per_m2;
    EXPECT_LT(rel(tau, p.tau), 0.01) << p.lambda << " nm: tau = " << tau;
  }
}

TEST(Rayleigh, CrossSectionFallsMonotonicallyWithWavelength) {
  // Majorants take the value at the short end of a band: check it is the max.
  double prev = rayleigh::cross_section_m2(229.0);
  for (double l = 229.1; l <= 2500.0; l += 0.1) {
    const double s = rayleigh::cross_section_m2(l);
    ASSERT_LT(s, prev) << l;
    prev = s;
  }
}

}  // namespace
}  // namespace skyfarm
