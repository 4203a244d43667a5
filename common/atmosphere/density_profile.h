// How much of a constituent there is at an altitude: a multiplier of its
// per-metre coefficients (dimensionless for custom constituents, molecules
// per m^3 for Earth's air and ozone, whose coefficients are cross-sections).
//
// Kinds:
//   exponential  rho(h) = exp(-h / H)
//   table        piecewise linear in h, 0 outside the table's altitudes
//   layers       Bruneton (2017) layers: clamp(a e^{s h} + l h + c, 0, 1)
//   us76_air     U.S. Standard Atmosphere 1976 number density (us76.h)
// Altitudes below 0 (round-off just under the ground) are evaluated at 0.
#pragma once
#include <variant>
#include <vector>

#include "common/atmosphere/atmosphere_spec.h"
#include "common/core/piecewise_linear.h"

namespace skyfarm {

class DensityProfile {
 public:
  static DensityProfile exponential(double scale_height_m);
  static DensityProfile table(PiecewiseLinear rho_of_h);  // made kZero outside
  static DensityProfile layers(std::vector<DensityLayer> layers);
  static DensityProfile us76_air();
  // From a validated request spec; throws std::invalid_argument on a bad one.
  static DensityProfile from_spec(const DensitySpec& spec);

  // rho(h).
  double eval(double altitude_m) const;
  // An upper bound of rho over [h0, h1], exact (attained) for every kind.
  double max_on(double h0_m, double h1_m) const;
  // Column integral of rho from h0 to h1 (m x density units).
  double column(double h0_m, double h1_m) const;

 private:
  struct Exponential { double H; };
  struct Table { PiecewiseLinear rho; };
  struct Layers { std::vector<DensityLayer> layers; };
  struct Us76Air {};
  using Kind = std::variant<Exponential, Table, Layers, Us76Air>;
  explicit DensityProfile(Kind kind) : kind_(std::move(kind)) {}

  Kind kind_;
};

}  // namespace skyfarm
