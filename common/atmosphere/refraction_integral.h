// Astronomical refraction by quadrature, after Auer & Standish (2000),
// "Astronomical refraction: computational method for all zenith angles",
// Astron. J. 119, 2472: with the ray's local zenith angle z as the variable,
//   R = - integral_{z_top}^{z_0}  r n'(r) / (n(r) + r n'(r))  dz,
// where along the ray n(r) r sin z = k.  The integrand stays finite at the
// horizon (z = 90 deg), unlike the classical form in r.  This is the
// continuous-profile estimator that the shell tracer (refracted_ray.h) is
// checked against.
//
// Parameters of refraction_integral:
//   profile            (n - 1)(altitude), planet and top radii (refractive_shells.h)
//   observer_altitude_m  above the ground; may be above the top
//   zenith_deg         apparent zenith angle, [0, 180]; beyond 90 deg the ray
//                      passes a tangent point and both branches are integrated
//   kink_altitudes_m   altitudes where n' jumps (layer bases): the quadrature
//                      is split there
// Returns the bending in radians, or NaN when the ray meets the ground.
// Assumes n + r n' > 0 (no duct): true for US76, whose steepest refractivity
// gradient is ~ -3e-8 /m against 1/r = 1.6e-7 /m.
#pragma once

#include <vector>

#include "common/atmosphere/refractive_shells.h"

namespace skyfarm {

double refraction_integral(const RefractivityProfile& profile, double observer_altitude_m, double zenith_deg,
                           const std::vector<double>& kink_altitudes_m = {}, int intervals_per_piece = 200);

// Layer bases of US76 (geometric altitude, m) for kink_altitudes_m.
std::vector<double> us76_layer_altitudes_m();

}  // namespace skyfarm
