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

// Atmospheric refraction correction (degrees, to ADD to a geometric elevation)
// of SPA eq. 42 (Reda & Andreas), for callers that want the apparent elevation;
// the renderer itself traces straight rays and uses the geometric position.
// Zero once the sun's upper limb is below the apparent horizon
// (elevation < -(0.26667 + 0.5667) degrees), as in NREL's spa.c.
double refraction_correction_deg(double elevation_deg, double pressure_hPa = 1010,
                                 double temperature_C = 10);

// Every intermediate quantity of the SPA (symbols of Reda & Andreas 2008), for
// validation against the paper's worked example and for callers that need them.
struct SolarPositionDetails {
  double delta_t_s = 0.0;                // ΔT = TT - UT used
  double julian_day = 0.0;               // JD (UT)
  double julian_ephemeris_day = 0.0;     // JDE (TT)
  double julian_century = 0.0;           // JC
  double julian_ephemeris_century = 0.0; // JCE
  double julian_ephemeris_millennium = 0.0;  // JME
  double heliocentric_longitude_deg = 0.0;   // L, [0, 360)
  double heliocentric_latitude_deg = 0.0;    // B
  double earth_sun_distance_au = 0.0;        // R
  double geocentric_longitude_deg = 0.0;     // Θ, [0, 360)
  double geocentric_latitude_deg = 0.0;      // β
  double nutation_longitude_deg = 0.0;       // Δψ
  double nutation_obliquity_deg = 0.0;       // Δε
  double mean_obliquity_arcsec = 0.0;        // ε0
  double true_obliquity_deg = 0.0;           // ε
  double aberration_deg = 0.0;               // Δτ
  double apparent_longitude_deg = 0.0;       // λ
  double greenwich_mean_sidereal_deg = 0.0;      // ν0, [0, 360)
  double greenwich_apparent_sidereal_deg = 0.0;  // ν
  double right_ascension_deg = 0.0;          // α, geocentric, [0, 360)
  double declination_deg = 0.0;              // δ, geocentric
  double hour_angle_deg = 0.0;               // H, observer local, [0, 360)
  double horizontal_parallax_deg = 0.0;      // ξ
  double parallax_right_ascension_deg = 0.0; // Δα
  double topocentric_right_ascension_deg = 0.0;  // α'
  double topocentric_declination_deg = 0.0;      // δ'
  double topocentric_hour_angle_deg = 0.0;       // H'
  double elevation_deg = 0.0;   // e0, topocentric, geometric (no refraction)
  double zenith_deg = 0.0;      // 90 - e0
  double azimuth_deg = 0.0;     // Φ, clockwise from north, [0, 360)
};

SolarPositionDetails solar_position_details(const Location& where, const UtcInstant& when,
                                            std::optional<double> delta_t_s = std::nullopt);

}  // namespace skyfarm
