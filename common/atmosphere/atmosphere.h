// A planet's atmosphere as the path tracer sees it: a sphere of radius
// planet_radius_m (the ground, Lambertian) inside a shell up to
// planet_radius_m + top_altitude_m, filled with constituents whose
// coefficients depend on altitude and wavelength only (horizontally uniform).
//
// All coefficients in m^-1, altitudes in m above the ground, wavelengths in nm.
// Build one from a request with build_atmosphere() (atmosphere_builder.h).
#pragma once
#include <string>
#include <vector>

#include "common/atmosphere/constituent.h"
#include "common/atmosphere/lambertian_ground.h"
#include "common/geometry/ray.h"

namespace skyfarm {

class Atmosphere {
 public:
  Atmosphere(double planet_radius_m, double top_altitude_m, std::vector<Constituent> constituents,
             LambertianGround ground);

  double planet_radius_m() const { return planet_radius_m_; }
  double top_altitude_m() const { return top_altitude_m_; }
  double top_radius_m() const { return planet_radius_m_ + top_altitude_m_; }
  const std::vector<Constituent>& constituents() const { return constituents_; }
  const LambertianGround& ground() const { return ground_; }

  // Sums over the constituents (0 above the top).
  double sigma_s(double altitude_m, double lambda_nm) const;
  double sigma_a(double altitude_m, double lambda_nm) const;
  double sigma_t(double altitude_m, double lambda_nm) const;

  // Optical depth of one constituent (or of all, index < 0) along the
  // vertical from h0 to h1: int sigma_t dh.  Exact column for altitude-
  // independent coefficients, adaptive quadrature otherwise.
  double vertical_optical_depth(double lambda_nm, double h0_m, double h1_m, int constituent = -1) const;

  // Optical depth int_0^t_max sigma_t(altitude(o + t d)) dt along a ray
  // (planet-centred coordinates), by adaptive quadrature split at the ray's
  // closest approach to the centre; stops at the ground if the ray meets it.
  // A reference for tests and reports, not for the hot path.
  double optical_depth(const Ray& ray, double t_max, double lambda_nm) const;

 private:
  double planet_radius_m_;
  double top_altitude_m_;
  std::vector<Constituent> constituents_;
  LambertianGround ground_;
};

}  // namespace skyfarm
