// Fresnel reflectance of a smooth interface: exact dielectric (with total
// internal reflection) and conductor (complex index of refraction).
//
// Parameters
//   cos_theta_i  cosine of the angle between the incident direction and the
//                interface normal, in [-1, 1].  For the dielectric a negative
//                value means the light arrives from the inside (the side the
//                normal points away from), and the relative index is inverted.
//                The conductor is opaque: only |cos_theta_i| matters.
//   eta          dielectric: relative index n_inside / n_outside, > 0 (glass
//                in air 1.5, water 1.333).
//   eta (complex) conductor: n + i k relative to the outside medium, n > 0,
//                k >= 0 (gold at 550 nm about 0.43 + 2.46i).  k = 0 reduces
//                to the dielectric seen from the outside.
//
// Results are reflectances (power fractions) in [0, 1]; the polarised forms
// give the s (perpendicular) and p (parallel) components, and the unpolarised
// reflectance is their average.
#pragma once

#include <complex>

namespace skyfarm::material {

struct PolarizedReflectance {
  double s = 0.0;  // |r_s|^2, electric field perpendicular to the plane of incidence
  double p = 0.0;  // |r_p|^2, electric field in the plane of incidence
  double average() const { return 0.5 * (s + p); }
};

PolarizedReflectance fresnel_dielectric_polarized(double cos_theta_i, double eta);
double fresnel_dielectric(double cos_theta_i, double eta);

PolarizedReflectance fresnel_conductor_polarized(double cos_theta_i, std::complex<double> eta);
double fresnel_conductor(double cos_theta_i, std::complex<double> eta);

}  // namespace skyfarm::material
