// U.S. Standard Atmosphere 1976 (NOAA-S/T 76-1562): temperature, pressure and
// densities of dry air versus geometric altitude.
//
// 0-86 km: the standard's defining layers (data/us_std_atm_1976_layers.csv)
// and hydrostatic formulas, evaluated analytically.  Above 86 km the standard
// is no longer a set of closed formulas; we continue with the AFGL (1986)
// U.S.-standard profile (data/ozone_profile.csv, p, T, n up to 120 km), scaled
// to be continuous at 86 km, and extrapolate exponentially beyond 120 km with
// the scale height of its last interval.
#pragma once

namespace skyfarm::us76 {

// Kinetic temperature T, K.
double temperature_K(double altitude_m);
// Pressure P, Pa.
double pressure_Pa(double altitude_m);
// Number density n of air molecules, m^-3.
double number_density_per_m3(double altitude_m);
// Mass density rho, kg m^-3.
double mass_density_kg_per_m3(double altitude_m);

// Geopotential altitude H (m') of a geometric altitude Z (m): H = r0 Z / (r0 + Z),
// r0 = 6 356 766 m (US76 eq. 18).
double geopotential_altitude_m(double geometric_altitude_m);

// Highest altitude of the standard's closed-form part (86 km geometric).
inline constexpr double kTopOfFormulas_m = 86000.0;

}  // namespace skyfarm::us76
