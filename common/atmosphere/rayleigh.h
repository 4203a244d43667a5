// Rayleigh scattering by air molecules, after Bucholtz (1995), "Rayleigh-
// scattering calculations for the terrestrial atmosphere", Appl. Opt. 34, 2765.
//
// Inputs: wavelength in nm (valid 200-4000 nm; the depolarisation table of
// data/rayleigh_bucholtz1995.csv reaches 1000 nm and is held at 2.730 % beyond).
#pragma once

namespace skyfarm::rayleigh {

// Number density of standard air (288.15 K, 1013.25 hPa), m^-3 (Bucholtz: 2.54743e19 cm^-3).
inline constexpr double kStandardAirDensity_per_m3 = 2.54743e25;

// (n_s - 1) of standard air (Peck & Reeder 1972, Bucholtz eqs. 4-5).
double refractive_index_minus_one(double lambda_nm);
// Depolarisation factor rho_n (Bucholtz Table 1, interpolated linearly).
double depolarization(double lambda_nm);
// King correction factor F_k = (6 + 3 rho_n) / (6 - 7 rho_n).
double king_factor(double lambda_nm);
// Total scattering cross-section per molecule, m^2 (Bucholtz eq. 8).
double cross_section_m2(double lambda_nm);
// Phase-function asymmetry parameter gamma = rho_n / (2 - rho_n) (Bucholtz eq. 13).
double phase_gamma(double lambda_nm);

}  // namespace skyfarm::rayleigh
