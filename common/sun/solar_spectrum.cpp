#include "common/sun/solar_spectrum.h"

#include "common/data/csv_table.h"

namespace skyfarm {

const PiecewiseLinear& am0_irradiance() {
  static const PiecewiseLinear e0 = [] {
    const auto csv = CsvTable::embedded("solar_am0.csv");
    return PiecewiseLinear(csv.column("wavelength_nm"), csv.column("irradiance_W_m2_nm"),
                           PiecewiseLinear::Outside::kZero, "AM0 solar spectrum");
  }();
  return e0;
}

}  // namespace skyfarm
