#include "common/atmosphere/ozone.h"

#include <algorithm>
#include <array>
#include <vector>

#include "common/core/constants.h"
#include "common/data/csv_table.h"

namespace skyfarm::ozone {
namespace {

constexpr const std::array<double, 5>& kTemperatures_K = kTableTemperatures_K;
constexpr std::array<const char*, 5> kColumns = {"sigma_203K_cm2", "sigma_223K_cm2", "sigma_243K_cm2",
                                                 "sigma_273K_cm2", "sigma_293K_cm2"};

// One PiecewiseLinear per tabulated temperature, m^2, zero outside the table.
// The table repeats 310.91 nm where two SCIAMACHY channels join (310.9108 and
// 310.91081): the second point is dropped so wavelengths increase strictly.
const std::array<PiecewiseLinear, 5>& cross_sections() {
  static const std::array<PiecewiseLinear, 5> tables = [] {
    const auto csv = CsvTable::embedded("ozone_cross_section.csv");
    const auto& wl = csv.column("wavelength_vacuum_nm");
    std::array<PiecewiseLinear, 5> out;
    for (std::size_t k = 0; k < kColumns.size(); ++k) {
      const auto& sigma = csv.column(kColumns[k]);
      std::vector<double> x, y;
      for (std::size_t i = 0; i < wl.size(); ++i) {
        if (!x.empty() && wl[i] <= x.back() + 1e-4) continue;
        x.push_back(wl[i]);
        y.push_back(std::max(0.0, sigma[i]) * 1e-4);  // cm^2 -> m^2, noise < 0 -> 0
      }
      out[k] = PiecewiseLinear(std::move(x), std::move(y), PiecewiseLinear::Outside::kZero, kColumns[k]);
    }
    return out;
  }();
  return tables;
}

}  // namespace

// Index k and weight t such that T lies between kTemperatures_K[k] and [k+1].
void temperature_bracket(double T, std::size_t* k, double* t) {
  if (T <= kTemperatures_K.front()) { *k = 0; *t = 0.0; return; }
  if (T >= kTemperatures_K.back()) { *k = kTemperatures_K.size() - 2; *t = 1.0; return; }
  std::size_t i = 0;
  while (T > kTemperatures_K[i + 1]) ++i;
  *k = i;
  *t = (T - kTemperatures_K[i]) / (kTemperatures_K[i + 1] - kTemperatures_K[i]);
}


double column_cross_section_m2(double lambda_nm, std::size_t column) { return cross_sections()[column](lambda_nm); }

double cross_section_m2(double lambda_nm, double temperature_K) {
  std::size_t k = 0;
  double t = 0.0;
  temperature_bracket(temperature_K, &k, &t);
  const auto& tables = cross_sections();
  return (1.0 - t) * tables[k](lambda_nm) + t * tables[k + 1](lambda_nm);
}

// Bilinear interpolation is a convex combination of the two bracketing
// temperature columns, so the max over every column that brackets [T0, T1]
// of each column's exact max over [l0, l1] bounds it.
double max_cross_section_m2(double l0_nm, double l1_nm, double T0_K, double T1_K) {
  std::size_t k0 = 0, k1 = 0;
  double t = 0.0;
  temperature_bracket(std::min(T0_K, T1_K), &k0, &t);
  temperature_bracket(std::max(T0_K, T1_K), &k1, &t);
  double m = 0.0;
  for (std::size_t k = k0; k <= k1 + 1; ++k) m = std::max(m, cross_sections()[k].max_on(l0_nm, l1_nm));
  return m;
}

const PiecewiseLinear& afgl_number_density() {
  static const PiecewiseLinear n = [] {
    const auto csv = CsvTable::embedded("ozone_profile.csv");
    return PiecewiseLinear(csv.column("altitude_m"), csv.column("o3_number_density_m3"),
                           PiecewiseLinear::Outside::kZero, "AFGL ozone profile");
  }();
  return n;
}

double afgl_column_du(double top_altitude_m) {
  return afgl_number_density().integral(0.0, top_altitude_m) / kDobsonUnit_per_m2;
}

DensityProfile scaled_profile(double column_du, double top_altitude_m) {
  const auto& n = afgl_number_density();
  const double scale = column_du / afgl_column_du(top_altitude_m);
  std::vector<double> x(n.x().begin(), n.x().end()), y(n.y().begin(), n.y().end());
  for (double& v : y) v *= scale;
  return DensityProfile::table(PiecewiseLinear(std::move(x), std::move(y)));
}

}  // namespace skyfarm::ozone
