// Where the observer is and how the sun is given (the request's "location",
// "time", "sun").  Plain data, validated by api/.
#pragma once
#include <optional>

#include "common/core/spectral_table.h"
#include "common/sun/utc_time.h"

namespace skyfarm {

// "location"
struct Location {
  double latitude_deg = 0.0;   // + north
  double longitude_deg = 0.0;  // + east
  double altitude_m = 0.0;     // above the planet's surface
};

// "sun"
struct SunSpec {
  std::optional<double> zenith_deg;   // both angles or neither; they replace
  std::optional<double> azimuth_deg;  // the position computed from "time"
  double angular_radius_deg = 0.2666; // 0 = a point sun
  std::optional<SpectralTable> irradiance;  // W m^-2 nm^-1 at the top of the atmosphere
};

}  // namespace skyfarm
