#include "common/atmosphere/rayleigh.h"

#include <algorithm>
#include <cmath>

#include "common/core/constants.h"
#include "common/core/piecewise_linear.h"
#include "common/data/csv_table.h"

namespace skyfarm::rayleigh {

// Peck & Reeder (1972) dispersion of standard air, as used by Bucholtz (eqs. 4, 5),
// with lambda in micrometres:
//   lambda >  0.23 um: (n_s - 1) 1e8 = 5791817 / (238.0185 - l^-2) + 167909 / (57.362 - l^-2)
//   lambda <= 0.23 um: (n_s - 1) 1e8 = 8060.51 + 2480990 / (132.274 - l^-2) + 17455.7 / (39.32957 - l^-2)
double refractive_index_minus_one(double lambda_nm) {
  const double inv_l2 = 1.0 / ((lambda_nm * 1e-3) * (lambda_nm * 1e-3));
  if (lambda_nm > 230.0) return (5791817.0 / (238.0185 - inv_l2) + 167909.0 / (57.362 - inv_l2)) * 1e-8;
  return (8060.51 + 2480990.0 / (132.274 - inv_l2) + 17455.7 / (39.32957 - inv_l2)) * 1e-8;
}

// Bucholtz Table 1: rho_n versus wavelength (0.2-1.0 um); 2.730 % beyond 1 um.
double depolarization(double lambda_nm) {
  static const PiecewiseLinear rho_n = [] {
    const auto csv = CsvTable::embedded("rayleigh_bucholtz1995.csv");
    return PiecewiseLinear(csv.column("wavelength_nm"), csv.column("depolarization_factor_rho_n"),
                           PiecewiseLinear::Outside::kClamp, "rayleigh depolarization");
  }();
  return rho_n(lambda_nm);
}

// King factor (Bucholtz eq. 9, after Young 1980).
double king_factor(double lambda_nm) {
  const double rho = depolarization(lambda_nm);
  return (6.0 + 3.0 * rho) / (6.0 - 7.0 * rho);
}

// Rayleigh cross-section per molecule (Bucholtz eq. 8):
//   sigma = 24 pi^3 (n_s^2 - 1)^2 / (lambda^4 N_s^2 (n_s^2 + 2)^2) F_k,
// with lambda and N_s in consistent units (here metres); (n_s^2 - 1) is formed
// as (n-1)(n+1) so no digits are lost to the 1 of n.
double cross_section_m2(double lambda_nm) {
  const double nm1 = refractive_index_minus_one(lambda_nm);
  const double n2_minus_1 = nm1 * (nm1 + 2.0);
  const double n2_plus_2 = (1.0 + nm1) * (1.0 + nm1) + 2.0;
  const double lambda_m = lambda_nm * 1e-9;
  const double lambda4 = (lambda_m * lambda_m) * (lambda_m * lambda_m);
  const double N_s = kStandardAirDensity_per_m3;
  return 24.0 * kPi * kPi * kPi * n2_minus_1 * n2_minus_1 / (lambda4 * N_s * N_s * n2_plus_2 * n2_plus_2) *
         king_factor(lambda_nm);
}

// gamma of the Rayleigh phase function with depolarisation (Bucholtz eq. 13).
double phase_gamma(double lambda_nm) {
  const double rho = depolarization(lambda_nm);
  return rho / (2.0 - rho);
}

}  // namespace skyfarm::rayleigh
