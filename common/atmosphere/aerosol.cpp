#include "common/atmosphere/aerosol.h"

#include <cmath>
#include <vector>

#include "common/data/csv_table.h"

namespace skyfarm::aerosol {

// The Elterman table gives beta(h)/beta(0) at 1 km steps to 50 km.  Above,
// knots every 300 m follow exp(-(h - 50 km) / 1.2 km) (linear interpolation
// between them overestimates the exponential by < 0.8 %) until the shape is
// below 1e-12 of the ground value or the top is reached.
DensityProfile elterman_shape(double top_altitude_m) {
  const auto csv = CsvTable::embedded("elterman_1968_aerosol.csv");
  std::vector<double> h = csv.column("altitude_m"), rho = csv.column("relative_to_surface");
  const double h50 = h.back(), rho50 = rho.back();
  for (double dh = 300.0; h50 + dh <= top_altitude_m + 300.0; dh += 300.0) {
    const double v = rho50 * std::exp(-dh / kUpperScaleHeight_m);
    if (v < 1e-12) break;
    h.push_back(h50 + dh);
    rho.push_back(v);
  }
  // Cut at the top: nothing above the atmosphere.
  std::vector<double> hc, rc;
  for (std::size_t i = 0; i < h.size() && h[i] <= top_altitude_m; ++i) {
    hc.push_back(h[i]);
    rc.push_back(rho[i]);
  }
  if (hc.back() < top_altitude_m && hc.size() < h.size()) {
    const std::size_t i = hc.size();
    const double t = (top_altitude_m - h[i - 1]) / (h[i] - h[i - 1]);
    hc.push_back(top_altitude_m);
    rc.push_back(rho[i - 1] + t * (rho[i] - rho[i - 1]));
  }
  return DensityProfile::table(PiecewiseLinear(std::move(hc), std::move(rc)));
}

double extinction_550_per_m(double tau_550, double top_altitude_m) {
  return tau_550 / elterman_shape(top_altitude_m).column(0.0, top_altitude_m);
}

double angstrom_factor(double lambda_nm, double angstrom_exponent) {
  return std::pow(lambda_nm / 550.0, -angstrom_exponent);
}

}  // namespace skyfarm::aerosol
