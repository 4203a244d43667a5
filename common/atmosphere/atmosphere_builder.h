// Turns the request's description of an atmosphere (AtmosphereSpec) into the
// physical model (Atmosphere):
//   earth       US76 air (Bucholtz Rayleigh), AFGL ozone scaled to ozone_du,
//               Elterman aerosols (unless aerosol is null or its depth is 0)
//   earth_clear the same without aerosols unless the spec gives some
//   custom      exactly the listed constituents
// Constituents that would contribute nothing (0 DU of ozone, aerosol depth 0)
// are left out, so a scene pays only for what it uses.
#pragma once

#include "common/atmosphere/atmosphere.h"
#include "common/atmosphere/atmosphere_spec.h"

namespace skyfarm {

Atmosphere build_atmosphere(const AtmosphereSpec& spec);

// The constituents of the Earth presets, exposed for tests and reports.
Constituent earth_air();
Constituent earth_ozone(double column_du, double top_altitude_m);
Constituent earth_aerosol(const AerosolSpec& aerosol, double top_altitude_m);

}  // namespace skyfarm
