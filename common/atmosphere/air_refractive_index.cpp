#include "common/atmosphere/air_refractive_index.h"

#include "common/atmosphere/us76.h"

namespace skyfarm::air {

// Ciddor (1996) eq. 1: 1e8 (n_as - 1) = k1/(k0 - s^2) + k3/(k2 - s^2), s = 1/lambda
// in µm^-1; k0 = 238.0185, k1 = 5 792 105, k2 = 57.362, k3 = 167 917 µm^-2.
double standard_refractivity(double lambda_nm) {
  const double lambda_um = lambda_nm * 1e-3;
  const double s2 = 1.0 / (lambda_um * lambda_um);
  return 1e-8 * (5792105.0 / (238.0185 - s2) + 167917.0 / (57.362 - s2));
}

// Ciddor eq. 12 with x_w = 0: Z = 1 - (p/T)(a0 + a1 t + a2 t^2) + (p/T)^2 d,
// t in C; a0 = 1.58123e-6 K/Pa, a1 = -2.9331e-8 /Pa, a2 = 1.1043e-10 /(K Pa),
// d = 1.83e-11 K^2/Pa^2.
double dry_air_compressibility(double pressure_Pa, double temperature_K) {
  const double t = temperature_K - 273.15;
  const double pt = pressure_Pa / temperature_K;
  return 1.0 - pt * (1.58123e-6 + t * (-2.9331e-8 + t * 1.1043e-10)) + pt * pt * 1.83e-11;
}

// Ciddor eq. 2 scales the standard refractivity to the CO2 content:
// (n_axs - 1) = (n_as - 1)(1 + 0.534e-6 (x_c - 450)); eqs. 4 and 9 scale it by
// density, rho_a / rho_axs, with rho = p M_a / (Z R T) (the molar mass cancels
// for dry air), rho_axs at 15 C and 101 325 Pa.
double refractivity(double lambda_nm, double pressure_Pa, double temperature_K, double co2_ppm) {
  constexpr double kStandardPressure_Pa = 101325.0;
  constexpr double kStandardTemperature_K = 288.15;
  static const double standard_z = dry_air_compressibility(kStandardPressure_Pa, kStandardTemperature_K);
  const double n_axs_minus_one = standard_refractivity(lambda_nm) * (1.0 + 0.534e-6 * (co2_ppm - 450.0));
  const double density_ratio = (pressure_Pa / kStandardPressure_Pa) * (kStandardTemperature_K / temperature_K) *
                               (standard_z / dry_air_compressibility(pressure_Pa, temperature_K));
  return n_axs_minus_one * density_ratio;
}

double us76_refractivity(double lambda_nm, double altitude_m) {
  return refractivity(lambda_nm, us76::pressure_Pa(altitude_m), us76::temperature_K(altitude_m));
}

}  // namespace skyfarm::air
