// The sun's position seen from a place on the Earth at a UTC instant.
// Implements the NREL Solar Position Algorithm (Reda & Andreas 2004/2008),
// see solar_position.cpp for the derivation and sources.
#pragma once
#include <optional>

#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm {

struct SolarPosition {
  double zenith_deg = 0.0;   // topocentric, geometric (no refraction), [0, 180]
  double azimuth_deg = 0.0;  // clockwise from north (east = 90), [0, 360)
  double earth_sun_distance_au = 1.0;  // R, astronomical units
  double declination_deg = 0.0;        // geocentric apparent declination
  double right_ascension_deg = 0.0;    // geocentric apparent right ascension, [0, 360)
  double hour_angle_deg = 0.0;         // observer local hour angle, [0, 360)
};

// Difference TT - UT in seconds for a decimal year (Espenak & Meeus 2006
// polynomial expressions, NASA eclipse web site), used when the caller gives none.
double delta_t_seconds(double decimal_year);

// Topocentric solar position for `where` (altitude_m above mean sea level) at
// `when`.  `delta_t_s` overrides delta_t_seconds().
SolarPosition solar_position(const Location& where, const UtcInstant& when,
                             std::optional<double> delta_t_s = std::nullopt);

}  // namespace skyfarm
