#include "common/atmosphere/atmosphere_builder.h"

#include <variant>

#include "common/atmosphere/aerosol.h"
#include "common/atmosphere/ozone.h"
#include "common/atmosphere/rayleigh.h"
#include "common/material/surface.h"

namespace skyfarm {
namespace {

LambertianGround ground_from_spec(const AlbedoSpec& albedo) {
  if (const double* rho = std::get_if<double>(&albedo)) return LambertianGround(PiecewiseLinear::constant(*rho));
  const auto& t = std::get<SpectralTable>(albedo);
  return LambertianGround(PiecewiseLinear(t.wavelengths_nm, t.values, PiecewiseLinear::Outside::kClamp,
                                          "ground albedo"));
}

Constituent custom_constituent(const ConstituentSpec& spec) {
  return Constituent{spec.name,
                     DensityProfile::from_spec(spec.density),
                     SpectralCoefficient::from_table(spec.scattering_per_m),
                     SpectralCoefficient::from_table(spec.absorption_per_m),
                     PhaseFunction::from_spec(spec.phase),
                     false};
}

}  // namespace

Constituent earth_air() {
  return Constituent{"air",
                     DensityProfile::us76_air(),
                     SpectralCoefficient::rayleigh_air(),
                     SpectralCoefficient::zero(),
                     PhaseFunction::rayleigh(rayleigh::depolarization(550.0)),
                     true};
}

Constituent earth_ozone(double column_du, double top_altitude_m) {
  return Constituent{"ozone",
                     ozone::scaled_profile(column_du, top_altitude_m),
                     SpectralCoefficient::zero(),
                     SpectralCoefficient::ozone(),
                     PhaseFunction::isotropic(),
                     false};
}

// Extinction k(lambda) = k_550 (lambda/550)^-alpha per unit of Elterman's
// shape, split by the single-scattering albedo omega_0.
Constituent earth_aerosol(const AerosolSpec& a, double top_altitude_m) {
  const double k_550 = aerosol::extinction_550_per_m(a.optical_depth_550, top_altitude_m);
  const double omega_0 = a.single_scattering_albedo;
  return Constituent{"aerosol",
                     aerosol::elterman_shape(top_altitude_m),
                     SpectralCoefficient::angstrom(omega_0 * k_550, a.angstrom_exponent),
                     SpectralCoefficient::angstrom((1.0 - omega_0) * k_550, a.angstrom_exponent),
                     a.phase == AerosolPhase::kCornetteShanks ? PhaseFunction::cornette_shanks(a.asymmetry)
                                                              : PhaseFunction::henyey_greenstein(a.asymmetry),
                     false};
}

Atmosphere build_atmosphere(const AtmosphereSpec& spec) {
  std::vector<Constituent> constituents;
  if (spec.preset == AtmospherePreset::kCustom) {
    for (const auto& c : spec.constituents) constituents.push_back(custom_constituent(c));
  } else {
    constituents.push_back(earth_air());
    if (spec.ozone_du > 0.0) constituents.push_back(earth_ozone(spec.ozone_du, spec.top_altitude_m));
    if (spec.aerosol && spec.aerosol->optical_depth_550 > 0.0)
      constituents.push_back(earth_aerosol(*spec.aerosol, spec.top_altitude_m));
  }
  return Atmosphere(spec.planet_radius_m, spec.top_altitude_m, std::move(constituents),
                    spec.ground_material ? ground_from_spec(material::Surface(*spec.ground_material)
                                                                .white_sky_albedo_table())
                                         : ground_from_spec(spec.ground_albedo));
}

}  // namespace skyfarm
