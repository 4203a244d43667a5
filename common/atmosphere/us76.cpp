#include "common/atmosphere/us76.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "common/core/piecewise_linear.h"
#include "common/data/csv_table.h"

namespace skyfarm::us76 {
namespace {

// Defining constants of US76 (NOAA-S/T 76-1562, Table 2 and §1.2).
constexpr double g0 = 9.80665;         // m s^-2
constexpr double r0 = 6356766.0;       // m, effective Earth radius for H
constexpr double R_star = 8314.32;     // J kmol^-1 K^-1
constexpr double M0 = 28.9644;         // kg kmol^-1, sea-level mean molar mass
constexpr double N_A = 6.022169e26;    // kmol^-1
constexpr double P0 = 101325.0;        // Pa

// One layer b of the piecewise-linear molecular-scale temperature T_M(H).
struct Layer {
  double H_b;    // base geopotential altitude, m'
  double T_Mb;   // base molecular-scale temperature, K
  double L_b;    // lapse rate, K per m'
  double P_b;    // base pressure, Pa
};

// The 7 layers of data/us_std_atm_1976_layers.csv.  Base pressures are
// recomputed from P0 with the hydrostatic formulas below (they reproduce the
// standard's published P_b to 7 digits) so the profile is exactly continuous.
const std::vector<Layer>& layers() {
  static const std::vector<Layer> table = [] {
    const auto csv = CsvTable::embedded("us_std_atm_1976_layers.csv");
    const auto& H = csv.column("base_geopotential_altitude_m");
    const auto& T = csv.column("base_molecular_scale_temperature_K");
    const auto& L = csv.column("lapse_rate_K_per_km_geopotential");
    std::vector<Layer> out;
    double P = P0;
    for (std::size_t b = 0; b < csv.rows(); ++b) {
      if (b > 0) {
        const Layer& prev = out.back();
        const double dH = H[b] - prev.H_b;
        P = (prev.L_b == 0.0)
                ? prev.P_b * std::exp(-g0 * M0 * dH / (R_star * prev.T_Mb))
                : prev.P_b * std::pow(prev.T_Mb / (prev.T_Mb + prev.L_b * dH), g0 * M0 / (R_star * prev.L_b));
      }
      out.push_back({H[b], T[b], L[b] / 1000.0, P});
    }
    return out;
  }();
  return table;
}

const Layer& layer_of(double H) {
  const auto& ls = layers();
  std::size_t b = 0;
  while (b + 1 < ls.size() && H >= ls[b + 1].H_b) ++b;
  return ls[b];
}

// Molecular-scale temperature T_M = T_Mb + L_b (H - H_b) (US76 eq. 23).
double molecular_scale_temperature(double H) {
  const Layer& l = layer_of(H);
  return l.T_Mb + l.L_b * (H - l.H_b);
}

// Hydrostatic pressure (US76 eqs. 33a/33b):
//   L_b != 0: P = P_b [T_Mb / (T_Mb + L_b (H - H_b))]^(g0 M0 / (R* L_b))
//   L_b == 0: P = P_b exp(-g0 M0 (H - H_b) / (R* T_Mb))
double pressure_formula(double H) {
  const Layer& l = layer_of(H);
  const double dH = H - l.H_b;
  if (l.L_b == 0.0) return l.P_b * std::exp(-g0 * M0 * dH / (R_star * l.T_Mb));
  return l.P_b * std::pow(l.T_Mb / (l.T_Mb + l.L_b * dH), g0 * M0 / (R_star * l.L_b));
}

// M/M0 between 80 and 86 km (US76 Table 8, 0.5 km steps): the kinetic
// temperature is T = T_M M/M0 (eq. 22); below 80 km M = M0.
double molar_mass_ratio(double Z) {
  static const PiecewiseLinear ratio(
      {80000, 80500, 81000, 81500, 82000, 82500, 83000, 83500, 84000, 84500, 85000, 85500, 86000},
      {1.000000, 0.999996, 0.999989, 0.999971, 0.999941, 0.999909, 0.999870, 0.999829, 0.999786, 0.999741,
       0.999694, 0.999641, 0.999579});
  return Z <= 80000.0 ? 1.0 : ratio(Z);
}

// --- Above 86 km: the AFGL U.S. standard profile, log-interpolated.
struct UpperProfile {
  std::vector<double> z, log_n, log_p, T;
};

const UpperProfile& upper_profile() {
  static const UpperProfile profile = [] {
    const auto csv = CsvTable::embedded("ozone_profile.csv");
    const auto& z = csv.column("altitude_m");
    const auto& n_cm3 = csv.column("air_number_density_cm3");
    const auto& p_hPa = csv.column("pressure_hPa");
    const auto& T = csv.column("temperature_K");
    UpperProfile u;
    for (std::size_t i = 0; i < csv.rows(); ++i) {
      if (z[i] < 80000.0) continue;  // keep one level below 86 km to bracket it
      u.z.push_back(z[i]);
      u.log_n.push_back(std::log(n_cm3[i] * 1e6));
      u.log_p.push_back(std::log(p_hPa[i] * 100.0));
      u.T.push_back(T[i]);
    }
    return u;
  }();
  return profile;
}

// Linear interpolation in a table, extrapolated linearly beyond its last two
// levels (for log-density: an exponential with the last scale height).
double interpolate_extrapolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  std::size_t i = 1;
  while (i + 1 < x.size() && at > x[i]) ++i;
  const double t = (at - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + t * (y[i] - y[i - 1]);
}

// Multiplicative factor that makes the AFGL continuation meet US76 at 86 km.
double upper_scale(const std::vector<double>& log_y, double value_at_86km) {
  const auto& u = upper_profile();
  return value_at_86km / std::exp(interpolate_extrapolate(u.z, log_y, kTopOfFormulas_m));
}

double clamp_altitude(double Z) { return std::max(Z, 0.0); }

}  // namespace

double geopotential_altitude_m(double Z) { return r0 * Z / (r0 + Z); }

double temperature_K(double altitude_m) {
  const double Z = clamp_altitude(altitude_m);
  if (Z <= kTopOfFormulas_m)
    return molecular_scale_temperature(geopotential_altitude_m(Z)) * molar_mass_ratio(Z);
  // Above 86 km: the AFGL temperatures, offset to be continuous at 86 km.
  const auto& u = upper_profile();
  static const double offset =
      temperature_K(kTopOfFormulas_m) - interpolate_extrapolate(u.z, u.T, kTopOfFormulas_m);
  return std::max(1.0, interpolate_extrapolate(u.z, u.T, std::min(Z, u.z.back())) + offset);
}

double pressure_Pa(double altitude_m) {
  const double Z = clamp_altitude(altitude_m);
  if (Z <= kTopOfFormulas_m) return pressure_formula(geopotential_altitude_m(Z));
  const auto& u = upper_profile();
  static const double scale = upper_scale(u.log_p, pressure_Pa(kTopOfFormulas_m));
  return scale * std::exp(interpolate_extrapolate(u.z, u.log_p, Z));
}

// n = N_A P / (R* T) (US76 eq. 35), with T the kinetic temperature.
double number_density_per_m3(double altitude_m) {
  const double Z = clamp_altitude(altitude_m);
  if (Z <= kTopOfFormulas_m) return N_A * pressure_Pa(Z) / (R_star * temperature_K(Z));
  const auto& u = upper_profile();
  static const double scale = upper_scale(u.log_n, number_density_per_m3(kTopOfFormulas_m));
  return scale * std::exp(interpolate_extrapolate(u.z, u.log_n, Z));
}

// rho = P M0 / (R* T_M) (US76 eq. 42); above 86 km from n with M(86 km).
double mass_density_kg_per_m3(double altitude_m) {
  const double Z = clamp_altitude(altitude_m);
  if (Z <= kTopOfFormulas_m) return pressure_Pa(Z) * M0 / (R_star * molecular_scale_temperature(geopotential_altitude_m(Z)));
  return number_density_per_m3(Z) * M0 * molar_mass_ratio(kTopOfFormulas_m) / N_A;
}

}  // namespace skyfarm::us76
