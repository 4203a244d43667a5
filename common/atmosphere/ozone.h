// Ozone absorption: temperature-dependent cross-sections (Bogumil et al. 2003,
// SCIAMACHY flight-model v4.0; data/ozone_cross_section.csv, 230-1066 nm,
// 203/223/243/273/293 K) times the AFGL (1986) U.S.-standard ozone profile
// (data/ozone_profile.csv) scaled to a total column in Dobson units.
#pragma once
#include <array>
#include <cstddef>

#include "common/atmosphere/density_profile.h"

namespace skyfarm::ozone {

// Absorption cross-section per molecule at wavelength lambda (vacuum nm) and
// temperature T, m^2: linear in wavelength, linear in temperature between the
// table's temperatures and held at 203 K / 293 K outside; 0 outside
// 230-1066 nm; the few slightly negative measured values (> 970 nm) read as 0.
double cross_section_m2(double lambda_nm, double temperature_K);

// The temperatures of the table's columns, K.
inline constexpr std::array<double, 5> kTableTemperatures_K = {203.0, 223.0, 243.0, 273.0, 293.0};
// Column k and weight t with T between columns k and k + 1 (t in [0, 1],
// clamped outside the table): cross_section_m2(l, T) =
// (1 - t) column_cross_section_m2(l, k) + t column_cross_section_m2(l, k + 1).
void temperature_bracket(double temperature_K, std::size_t* k, double* t);
// The cross-section of one temperature column, m^2.
double column_cross_section_m2(double lambda_nm, std::size_t column);

// An upper bound of cross_section_m2 over [l0, l1] x [T0, T1].
double max_cross_section_m2(double l0_nm, double l1_nm, double T0_K, double T1_K);

// The AFGL U.S.-standard ozone number density (m^-3) versus altitude,
// piecewise linear between its levels (0-120 km).
const PiecewiseLinear& afgl_number_density();

// Total column of afgl_number_density() from 0 to top, in Dobson units.
double afgl_column_du(double top_altitude_m);

// The AFGL profile scaled so that its column from 0 to `top_altitude_m` is
// `column_du` Dobson units.
DensityProfile scaled_profile(double column_du, double top_altitude_m);

}  // namespace skyfarm::ozone
