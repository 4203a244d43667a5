// A constituent's scattering or absorption coefficient per unit of its density
// (per metre for custom constituents, a cross-section in m^2 for Earth's air
// and ozone), as a function of wavelength and, for ozone, of altitude through
// the temperature there.
//
// Kinds:
//   zero           0
//   table          user table over wavelength, linear between points, held at
//                  the end values outside (one point = constant)
//   rayleigh_air   Bucholtz (1995) cross-section (rayleigh.h)
//   ozone          Bogumil cross-section at the US76 temperature of the altitude
//   angstrom       k_550 (lambda / 550 nm)^-alpha
#pragma once
#include <variant>

#include "common/core/piecewise_linear.h"
#include "common/core/spectral_table.h"

namespace skyfarm {

class SpectralCoefficient {
 public:
  static SpectralCoefficient zero();
  static SpectralCoefficient table(PiecewiseLinear k_of_lambda);
  // An empty table means zero.
  static SpectralCoefficient from_table(const SpectralTable& table);
  static SpectralCoefficient rayleigh_air();
  static SpectralCoefficient ozone();
  static SpectralCoefficient angstrom(double k_550, double alpha);

  double eval(double lambda_nm, double altitude_m) const;
  // An upper bound over [l0, l1] x [h0, h1].
  double max_on(double l0_nm, double l1_nm, double h0_m, double h1_m) const;
  bool is_zero() const;
  // True when the value does not depend on altitude.
  bool altitude_independent() const;
  // True for the ozone kind (the only one that depends on altitude, through
  // the US76 temperature; see ozone.h for its temperature columns).
  bool is_ozone() const { return !altitude_independent(); }

 private:
  struct Zero {};
  struct Table { PiecewiseLinear k; };
  struct RayleighAir {};
  struct Ozone {};
  struct Angstrom { double k_550, alpha; };
  using Kind = std::variant<Zero, Table, RayleighAir, Ozone, Angstrom>;
  explicit SpectralCoefficient(Kind kind) : kind_(std::move(kind)) {}

  Kind kind_;
};

}  // namespace skyfarm
