// The extraterrestrial solar spectral irradiance at 1 AU: ASTM E-490-00a AM0
// (data/solar_am0.csv, 119.5 nm - 1000 um, W m^-2 nm^-1; data/README.md §2).
#pragma once
#include "common/core/piecewise_linear.h"

namespace skyfarm {

// E_0(lambda) at 1 AU, W m^-2 nm^-1, linear between the table's points, 0 outside.
const PiecewiseLinear& am0_irradiance();

}  // namespace skyfarm
