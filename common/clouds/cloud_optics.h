// The optics of cloud particles, taken as grey across the visible: one
// extinction per unit water content, one single-scattering albedo and one
// phase function for every wavelength a path carries.
//
// Why grey: cloud droplets (r_eff 4-25 um) have size parameters
// 2 pi r / lambda of 30-400 over 380-830 nm, where the Mie extinction
// efficiency is within a few per cent of its geometric-optics limit 2 and the
// phase function's shape changes little; water absorbs almost nothing there
// (imaginary index < 1e-7 below 800 nm).  The tables are Mie computations at
// 544.7 nm (data/cloud_mie_*.csv) and are used at every wavelength.
//
// Parameters
//   particle             water (Mie droplets) or ice (cirrus crystals)
//   effective_radius_um  water: 0.5-25 um (the summary table's range; the
//                        extinction, albedo and g interpolated linearly in
//                        it); ice: any finite radius > 0 (geometric optics,
//                        Q_ext = 2: sigma_t = 3 IWC / (2 rho_ice r_eff))
// Outputs (CloudOptics)
//   extinction_per_g_m3  sigma_t in m^-1 per g m^-3 of condensed water
//   albedo               single-scattering albedo
//   phase                the phase function (PhaseFunction, sampled exactly):
//                        water: the tabulated Mie phase of r_eff = 10 um (glory,
//                        fogbow, forward peak) for every radius, built once
//                        and shared; ice: 1/2 HG(0.98) + 1/2 HG(0.52)
//                        (diffraction + roughened-crystal ray optics, g = 0.75;
//                        see the .cpp), tabulated so that it is sampled exactly
//   asymmetry            <cos theta> of the particle at its radius: water, the
//                        Mie table's g (0.76-0.875; the shared phase's own
//                        mean cosine is 0.864, the 10 um value); ice, 0.75
//
// Throws std::invalid_argument for a radius outside the range.
#pragma once
#include "common/atmosphere/phase_function.h"
#include "common/clouds/cloud_spec.h"

namespace skyfarm {

struct CloudOptics {
  double extinction_per_g_m3 = 0.0;
  double albedo = 1.0;
  PhaseFunction phase;
  double asymmetry = 0.0;
};

CloudOptics cloud_optics(CloudParticle particle, double effective_radius_um);

}  // namespace skyfarm
