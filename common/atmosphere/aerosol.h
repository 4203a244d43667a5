// Aerosols: the vertical shape of Elterman's (1968) continental
// profile (data/elterman_1968_aerosol.csv, 0-50 km, continued above 50 km by
// an exponential of scale height 1.2 km), scaled so that the vertical optical
// depth from the ground to the top is tau_550 at 550 nm; the Angstrom law
// tau(lambda) = tau_550 (lambda / 550 nm)^-alpha for other wavelengths;
// single-scattering albedo omega_0 splits extinction into scattering and
// absorption; Henyey-Greenstein or Cornette-Shanks phase of asymmetry g.
#pragma once

#include "common/atmosphere/density_profile.h"

namespace skyfarm::aerosol {

// Scale height of the exponential continuation above 50 km, m.
inline constexpr double kUpperScaleHeight_m = 1200.0;

// Elterman's shape, 1 at the ground, zero above top_altitude_m.
DensityProfile elterman_shape(double top_altitude_m);

// Extinction coefficient at 550 nm per unit of elterman_shape() that gives a
// vertical optical depth tau_550 between the ground and the top.
double extinction_550_per_m(double tau_550, double top_altitude_m);

// Angstrom's law: the ratio tau(lambda) / tau(550 nm).
double angstrom_factor(double lambda_nm, double angstrom_exponent);

}  // namespace skyfarm::aerosol
