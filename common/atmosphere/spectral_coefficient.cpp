#include "common/atmosphere/spectral_coefficient.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/atmosphere/ozone.h"
#include "common/atmosphere/rayleigh.h"
#include "common/atmosphere/us76.h"
#include "common/core/overloaded.h"

namespace skyfarm {
namespace {

// The US76 temperature range over [h0, h1]: the profile is piecewise linear
// in geopotential altitude with kinks at the layer bases, so its extremes lie
// at the ends or at those kinks (AFGL levels above 86 km).
void temperature_range(double h0, double h1, double* T_min, double* T_max) {
  static constexpr double kKinks[] = {11019.1, 20063.1, 32161.9, 47350.1, 51412.5, 71802.0, 86000.0,
                                      90000.0,  95000.0,  100000.0, 105000.0, 110000.0, 115000.0, 120000.0};
  *T_min = std::min(us76::temperature_K(h0), us76::temperature_K(h1));
  *T_max = std::max(us76::temperature_K(h0), us76::temperature_K(h1));
  for (double k : kKinks) {
    if (k <= h0 || k >= h1) continue;
    const double T = us76::temperature_K(k);
    *T_min = std::min(*T_min, T);
    *T_max = std::max(*T_max, T);
  }
}

}  // namespace

SpectralCoefficient SpectralCoefficient::zero() { return SpectralCoefficient(Zero{}); }

SpectralCoefficient SpectralCoefficient::table(PiecewiseLinear k_of_lambda) {
  for (double v : k_of_lambda.y())
    if (v < 0.0) throw std::invalid_argument("spectral coefficient: values must be >= 0");
  return SpectralCoefficient(Table{std::move(k_of_lambda)});
}

SpectralCoefficient SpectralCoefficient::from_table(const SpectralTable& t) {
  if (t.wavelengths_nm.empty()) return zero();
  return table(PiecewiseLinear(t.wavelengths_nm, t.values, PiecewiseLinear::Outside::kClamp, "spectral table"));
}

SpectralCoefficient SpectralCoefficient::rayleigh_air() { return SpectralCoefficient(RayleighAir{}); }
SpectralCoefficient SpectralCoefficient::ozone() { return SpectralCoefficient(Ozone{}); }
SpectralCoefficient SpectralCoefficient::angstrom(double k_550, double alpha) {
  return SpectralCoefficient(Angstrom{k_550, alpha});
}

double SpectralCoefficient::eval(double lambda_nm, double altitude_m) const {
  return std::visit(
      Overloaded{
          [](const Zero&) { return 0.0; },
          [lambda_nm](const Table& t) { return t.k(lambda_nm); },
          [lambda_nm](const RayleighAir&) { return rayleigh::cross_section_m2(lambda_nm); },
          [lambda_nm, altitude_m](const Ozone&) {
            return ozone::cross_section_m2(lambda_nm, us76::temperature_K(altitude_m));
          },
          [lambda_nm](const Angstrom& a) { return a.k_550 * std::pow(lambda_nm / 550.0, -a.alpha); },
      },
      kind_);
}

double SpectralCoefficient::max_on(double l0, double l1, double h0, double h1) const {
  return std::visit(Overloaded{
                        [](const Zero&) { return 0.0; },
                        [l0, l1](const Table& t) { return t.k.max_on(l0, l1); },
                        // The Rayleigh cross-section falls monotonically with wavelength
                        // (lambda^-4 times slowly varying factors; checked by a test).
                        [l0](const RayleighAir&) { return rayleigh::cross_section_m2(l0); },
                        [l0, l1, h0, h1](const Ozone&) {
                          double T_min = 0.0, T_max = 0.0;
                          temperature_range(std::max(h0, 0.0), std::max(h1, 0.0), &T_min, &T_max);
                          return ozone::max_cross_section_m2(l0, l1, T_min, T_max);
                        },
                        // A power law is monotone: its max is at one end.
                        [l0, l1](const Angstrom& a) {
                          return a.k_550 * std::max(std::pow(l0 / 550.0, -a.alpha), std::pow(l1 / 550.0, -a.alpha));
                        },
                    },
                    kind_);
}

bool SpectralCoefficient::is_zero() const {
  if (std::holds_alternative<Zero>(kind_)) return true;
  if (const auto* t = std::get_if<Table>(&kind_)) {
    for (double v : t->k.y())
      if (v != 0.0) return false;
    return true;
  }
  if (const auto* a = std::get_if<Angstrom>(&kind_)) return a->k_550 == 0.0;
  return false;
}

bool SpectralCoefficient::altitude_independent() const { return !std::holds_alternative<Ozone>(kind_); }

}  // namespace skyfarm
