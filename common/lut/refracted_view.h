// The LUT sky with refraction ("atmosphere.refraction"): an approximation
// made in the look-up alone, the tables themselves staying those of straight
// rays.
//
// The sun disk.  A view direction at apparent elevation e sees, at each
// bin's centre wavelength, the true direction e - R(e) (RefractionTable at
// the observer's altitude: the ray-traced refraction of US76, as the path
// tracer's); the disk shows where that true direction lies in the sun, so it
// is lifted, flattened and has its coloured rims, as in the path tracer.  Its
// transmittance is the table's along the apparent direction (the bent path
// leaves the dense low air at about that angle; the straight ray towards
// the true direction below the horizon would meet the ground).
//
// The sky.  The scattered light seen along a bent ray is gathered mostly
// near the observer, where the ray still runs at its apparent elevation, so
// the sky-view table is read at the apparent direction, except that the
// horizon moves: the apparent horizon (the ray grazing the ground, e_min)
// is shown where the straight-ray tables have theirs (the geometric horizon
// e_h, the dip), the shift e_h - e_min fading linearly to nothing 10 degrees
// away.  For a sea-level observer the two horizons nearly agree and the sky
// is the straight one; from 2 km the ground rises by 0.1 deg.
// Views from above the atmosphere (ray marches) stay straight.
#pragma once

#include <optional>

#include <glm/vec3.hpp>

#include "common/atmosphere/refraction_table.h"

namespace skyfarm {

class RefractedView {
 public:
  RefractedView(double observer_altitude_m, double planet_radius_m, double top_altitude_m);

  // The direction the sky-view table is read in for the unit view direction v.
  glm::dvec3 sky_direction(const glm::dvec3& v) const;
  // The true direction of the source seen along v at lambda; nullopt where the ray meets the ground.
  std::optional<glm::dvec3> true_direction(const glm::dvec3& v, double lambda_nm) const;
  // The inverse: where a source in the true direction d appears (at
  // lambda), and dw_apparent / dw_true there (its disk's solid angle shrinks
  // by it); nullopt where the planet hides it.
  struct Apparent {
    glm::dvec3 direction;
    double solid_angle_ratio = 1.0;
  };
  std::optional<Apparent> apparent_direction(const glm::dvec3& d, double lambda_nm) const;
  const RefractionTable& table() const { return table_; }

 private:
  RefractionTable table_;
  double horizon_shift_deg_ = 0.0;  // e_h - e_min at 550 nm
  double apparent_horizon_deg_ = 0.0;
};

}  // namespace skyfarm
