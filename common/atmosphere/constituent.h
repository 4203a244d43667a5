// One constituent of an atmosphere: how much of it there is at each altitude,
// how strongly it scatters and absorbs per unit of that amount, and its phase
// function.  sigma_s(h, lambda) = rho(h) k_s(lambda, h), likewise sigma_a.
#pragma once
#include <string>

#include "common/atmosphere/density_profile.h"
#include "common/atmosphere/phase_function.h"
#include "common/atmosphere/spectral_coefficient.h"

namespace skyfarm {

struct Constituent {
  std::string name;                  // "air", "ozone", "aerosol" or the request's name
  DensityProfile density;            // rho(h)
  SpectralCoefficient k_scattering;  // per unit density
  SpectralCoefficient k_absorption;  // per unit density
  PhaseFunction phase;
  // Earth's air: the Rayleigh depolarisation follows Bucholtz's rho_n(lambda)
  // instead of the fixed value in `phase`.
  bool rayleigh_depolarization_from_bucholtz = false;

  // Scattering coefficient sigma_s, m^-1.
  double sigma_s(double altitude_m, double lambda_nm) const;
  // Absorption coefficient sigma_a, m^-1.
  double sigma_a(double altitude_m, double lambda_nm) const;
  double sigma_t(double altitude_m, double lambda_nm) const {
    return sigma_s(altitude_m, lambda_nm) + sigma_a(altitude_m, lambda_nm);
  }
  // The phase function at a wavelength.
  PhaseFunction phase_at(double lambda_nm) const;
  bool scatters() const { return !k_scattering.is_zero(); }
  bool absorbs() const { return !k_absorption.is_zero(); }
};

}  // namespace skyfarm
