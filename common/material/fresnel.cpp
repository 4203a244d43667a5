#include "common/material/fresnel.h"

#include <algorithm>
#include <cmath>

namespace skyfarm::material {

// Fresnel equations for a smooth dielectric interface (Born & Wolf,
// "Principles of Optics", §1.5.2, the Fresnel formulae for the reflected
// amplitudes), with the transmitted cosine from Snell's law
//   sin(theta_t) = sin(theta_i) / eta:
//   r_s = (cos_i - eta cos_t) / (cos_i + eta cos_t)
//   r_p = (eta cos_i - cos_t) / (eta cos_i + cos_t)
// and total internal reflection (sin(theta_t) >= 1) reflecting everything.
PolarizedReflectance fresnel_dielectric_polarized(double cos_theta_i, double eta) {
  double cos_i = std::clamp(cos_theta_i, -1.0, 1.0);
  if (cos_i < 0.0) {  // from the inside: swap the media
    eta = 1.0 / eta;
    cos_i = -cos_i;
  }
  if (eta == 1.0) return {0.0, 0.0};  // no interface (and no 0/0 at grazing)
  const double sin2_i = std::max(0.0, 1.0 - cos_i * cos_i);
  const double sin2_t = sin2_i / (eta * eta);
  if (sin2_t >= 1.0) return {1.0, 1.0};
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return {r_s * r_s, r_p * r_p};
}

double fresnel_dielectric(double cos_theta_i, double eta) {
  return fresnel_dielectric_polarized(cos_theta_i, eta).average();
}

// The same formulae with a complex relative index eta = n + i k (Born & Wolf,
// §14.2, reflection at a metal surface: the Fresnel formulae hold with the
// complex index).  cos_t = sqrt(1 - sin^2(theta_i) / eta^2) is complex; the
// principal square root picks the transmitted wave that decays into the
// metal for k > 0 and gives |r| = 1 in total internal reflection for k = 0.
PolarizedReflectance fresnel_conductor_polarized(double cos_theta_i, std::complex<double> eta) {
  const double cos_i = std::min(std::abs(cos_theta_i), 1.0);
  if (eta == std::complex<double>(1.0, 0.0)) return {0.0, 0.0};  // no interface
  const double sin2_i = std::max(0.0, 1.0 - cos_i * cos_i);
  const std::complex<double> sin2_t = sin2_i / (eta * eta);
  const std::complex<double> cos_t = std::sqrt(1.0 - sin2_t);
  const std::complex<double> r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const std::complex<double> r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  // |r|^2 cannot exceed 1 for a passive medium; the clamp removes rounding.
  return {std::min(std::norm(r_s), 1.0), std::min(std::norm(r_p), 1.0)};
}

double fresnel_conductor(double cos_theta_i, std::complex<double> eta) {
  return fresnel_conductor_polarized(cos_theta_i, eta).average();
}

}  // namespace skyfarm::material
