// The sun as a light source:
//   direction        from the solar position algorithm for the request's place
//                    and time, or the request's zenith / azimuth
//   angular_radius   of the disk, 0.2666 deg by default; 0 = a point (delta) sun
//   irradiance       E(lambda) at the top of the atmosphere on a surface facing
//                    the sun, W m^-2 nm^-1: AM0 / R^2 (R in AU, 1 without a time)
//                    or the request's table as given
// The disk is uniformly bright (no limb darkening): its radiance is
//   L(lambda) = E(lambda) / (pi sin^2 alpha),
// since a uniform disk of angular radius alpha gives E = L int cos dw =
// L pi sin^2 alpha.  Directions are sampled uniformly over its solid angle
// Omega = 2 pi (1 - cos alpha) = 4 pi sin^2(alpha / 2).
#pragma once
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "common/core/piecewise_linear.h"
#include "common/sampling/warps.h"
#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm {

class Sun {
 public:
  Sun(double zenith_deg, double azimuth_deg, double angular_radius_deg, PiecewiseLinear irradiance);

  // The sun of a request: position from `time` at `where` unless the spec
  // gives the angles; irradiance from the spec's table or AM0 / R^2.  Throws
  // std::invalid_argument when there is neither a time nor both angles.
  static Sun from_spec(const SunSpec& spec, const Location& where, const std::optional<UtcInstant>& time);

  double zenith_deg() const { return zenith_deg_; }
  double azimuth_deg() const { return azimuth_deg_; }
  // Earth-Sun distance used for the irradiance, AU (1 when no time was given).
  double distance_au() const { return distance_au_; }
  // Unit vector towards the sun's centre, observer frame (z up, y north, x east).
  const glm::dvec3& direction() const { return direction_; }
  double angular_radius_rad() const { return alpha_; }
  bool is_point() const { return alpha_ == 0.0; }
  double solid_angle_sr() const;

  double irradiance(double lambda_nm) const { return irradiance_(lambda_nm); }
  // Radiance inside the disk; for a point sun, the irradiance (a delta in direction).
  double radiance(double lambda_nm) const;
  // True when w (unit) points into the disk.
  bool contains(const glm::dvec3& w) const;
  // A direction uniformly distributed over the disk, with its pdf (1/sr;
  // for a point sun the direction itself and pdf 1 of a delta).
  glm::dvec3 sample_direction(double u1, double u2, double* pdf) const;
  double pdf(const glm::dvec3& w) const;

 private:
  double zenith_deg_, azimuth_deg_, distance_au_ = 1.0;
  double alpha_;
  double cos_alpha_;
  // Constants of the disk, computed once (each costs a sine, and the path
  // tracer asks for them at every sun sample): pi sin^2(alpha) of the
  // radiance, the bound on 1 - cos of contains(), the solid angle, and the
  // cone height 1 - cos(alpha) of sample_direction().
  double pi_sin2_alpha_;
  double contains_bound_;
  double solid_angle_;
  double cone_height_;
  glm::dvec3 direction_;
  Frame frame_;
  PiecewiseLinear irradiance_;
};

}  // namespace skyfarm
