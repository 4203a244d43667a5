// Test support: a sun given by its angles (no time), as many tests need.
#pragma once
#include <optional>

#include "common/sun/sun.h"

namespace skyfarm::testing {

inline SunSpec sun_spec(double zenith_deg, double azimuth_deg, double angular_radius_deg = 0.2666) {
  SunSpec s;
  s.zenith_deg = zenith_deg;
  s.azimuth_deg = azimuth_deg;
  s.angular_radius_deg = angular_radius_deg;
  return s;
}

inline Sun sun_from_angles(double zenith_deg, double azimuth_deg, double angular_radius_deg = 0.2666) {
  return Sun::from_spec(sun_spec(zenith_deg, azimuth_deg, angular_radius_deg), Location{}, std::nullopt);
}

}  // namespace skyfarm::testing
