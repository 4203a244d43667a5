#include "common/atmosphere/constituent.h"

#include "common/atmosphere/rayleigh.h"

namespace skyfarm {

double Constituent::sigma_s(double altitude_m, double lambda_nm) const {
  if (k_scattering.is_zero()) return 0.0;
  return density.eval(altitude_m) * k_scattering.eval(lambda_nm, altitude_m);
}

double Constituent::sigma_a(double altitude_m, double lambda_nm) const {
  if (k_absorption.is_zero()) return 0.0;
  return density.eval(altitude_m) * k_absorption.eval(lambda_nm, altitude_m);
}

PhaseFunction Constituent::phase_at(double lambda_nm) const {
  if (rayleigh_depolarization_from_bucholtz) return PhaseFunction::rayleigh(rayleigh::depolarization(lambda_nm));
  return phase;
}

}  // namespace skyfarm
