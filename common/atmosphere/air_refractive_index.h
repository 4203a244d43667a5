// Refractive index of dry air, Ciddor (1996), "Refractive index of air: new
// equations for the visible and near infrared", Appl. Opt. 35, 1566-1573.
//
// Why Ciddor rather than Edlén (1966) / Birch & Downs (1993, 1994): Ciddor's
// equation is the one the IAG recommends and NIST's Engineering Metrology
// Toolbox offers first; it is derived from the molar refractivity and BIPM's
// density equation, so it extrapolates to the cold, thin air of the upper
// atmosphere through density alone, whereas the Edlén family is an empirical
// fit in (p, t) around laboratory conditions.  In the visible the two agree to
// a few 1e-9 (the tests compare them).
//
// Parameters (all functions):
//   lambda_nm       vacuum wavelength, nm (Ciddor: 230-1690 nm)
//   pressure_Pa     total pressure, Pa
//   temperature_K   temperature, K
//   co2_ppm         CO2 mole fraction, µmol/mol (Ciddor's standard air: 450)
// Humidity is zero throughout (the atmosphere model is dry air).
#pragma once

namespace skyfarm::air {

// Ciddor's standard-air CO2 content, µmol/mol.
inline constexpr double kStandardCo2_ppm = 450.0;

// (n - 1) of standard dry air (15 C, 101 325 Pa, 450 ppm CO2): Ciddor eq. 1.
double standard_refractivity(double lambda_nm);

// Compressibility Z of dry air (BIPM-81/91 as quoted by Ciddor, eq. 12, x_w = 0).
double dry_air_compressibility(double pressure_Pa, double temperature_K);

// (n - 1) of dry air at (p, T): Ciddor eqs. 2, 4, 9 with x_w = 0.
double refractivity(double lambda_nm, double pressure_Pa, double temperature_K,
                    double co2_ppm = kStandardCo2_ppm);

// (n - 1) at a geometric altitude of the U.S. Standard Atmosphere 1976
// (common/atmosphere/us76.h): Ciddor at the standard's pressure and temperature.
double us76_refractivity(double lambda_nm, double altitude_m);

}  // namespace skyfarm::air
