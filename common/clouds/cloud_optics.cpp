#include "common/clouds/cloud_optics.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "common/core/constants.h"
#include "common/data/csv_table.h"

namespace skyfarm {
namespace {

// Density of ice Ih near 0 C, kg m^-3 (Hobbs 1974, Ice Physics).
constexpr double kIceDensity_kg_m3 = 917.0;

// The water summary table (data/cloud_mie_water_summary.csv): libRadtran's
// MIEV0 results for gamma-distributed droplets at 544.7 nm, r_eff 0.5-25 um.
struct WaterSummary {
  std::vector<double> r_eff_um, extinction_per_m, albedo, asymmetry;
};

const WaterSummary& water_summary() {
  static const WaterSummary summary = [] {
    const CsvTable csv = CsvTable::embedded("cloud_mie_water_summary.csv");
    WaterSummary s;
    s.r_eff_um = csv.column("effective_radius_um");
    // The table gives km^-1 for 1 g m^-3; the renderer works in metres.
    for (double k : csv.column("extinction_per_km_for_LWC_1g_m3")) s.extinction_per_m.push_back(k * 1e-3);
    s.albedo = csv.column("single_scattering_albedo");
    s.asymmetry = csv.column("asymmetry_parameter_g");
    return s;
  }();
  return summary;
}

// The Mie phase function of r_eff = 10 um (data/cloud_mie_phase_water_reff10um.csv),
// built once: 801 knots, its cumulative table is shared by every copy.
const PhaseFunction& water_phase() {
  static const PhaseFunction phase = [] {
    const CsvTable csv = CsvTable::embedded("cloud_mie_phase_water_reff10um.csv");
    return PhaseFunction::tabulated(csv.column("scattering_angle_deg"), csv.column("phase_function_4pi_normalised"));
  }();
  return phase;
}

// Ice crystals (cirrus): a two-term Henyey-Greenstein model,
//   p(mu) = 1/2 HG(mu; 0.98) + 1/2 HG(mu; 0.52),   g = 0.75.
// Why: for crystals much larger than the wavelength, geometric optics splits
// the scattered energy into two equal halves (extinction paradox, Q_ext = 2;
// van de Hulst 1957, Light Scattering by Small Particles, sec. 8.22): the
// diffraction peak, narrow (a few degrees for D ~ 50 um at 550 nm), modelled
// by HG(0.98), and the light refracted and reflected by the crystals.  For
// severely roughened crystals the refracted part is smooth and featureless (no
// 22/46 degree halos) and the total asymmetry parameter in the visible is
// ~0.75 (Yang et al. 2013, J. Atmos. Sci. 70, 330-347, severely roughened
// aggregates; Baum et al. 2014, J. Quant. Spectrosc. Radiat. Transfer 146,
// 123-139, MODIS Collection 6 ice model g ~ 0.75), so g_ray = 2 * 0.75 - 0.98 = 0.52.
// Tabulated on a fine angle grid (0.01 deg in the diffraction peak) so that it
// is sampled exactly by PhaseFunction::tabulated.
double hg(double mu, double g) {
  const double d = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

const PhaseFunction& ice_phase() {
  static const PhaseFunction phase = [] {
    std::vector<double> angles, values;
    auto add_range = [&](double from, double to, double step) {
      const int n = static_cast<int>(std::lround((to - from) / step));
      for (int i = 0; i < n; ++i) angles.push_back(from + i * step);
    };
    add_range(0.0, 5.0, 0.01);
    add_range(5.0, 30.0, 0.05);
    add_range(30.0, 180.0, 0.25);
    angles.push_back(180.0);
    for (double a : angles) {
      const double mu = std::cos(a * kPi / 180.0);
      values.push_back(0.5 * hg(mu, 0.98) + 0.5 * hg(mu, 0.52));
    }
    return PhaseFunction::tabulated(angles, values);
  }();
  return phase;
}

// Linear interpolation in x on increasing knots xs (x within [xs.front(), xs.back()]).
double interpolate(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  std::size_t i = 1;
  while (i + 1 < xs.size() && xs[i] < x) ++i;
  const double t = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
  return ys[i - 1] + t * (ys[i] - ys[i - 1]);
}

}  // namespace

CloudOptics cloud_optics(CloudParticle particle, double effective_radius_um) {
  CloudOptics optics;
  if (particle == CloudParticle::kWater) {
    const WaterSummary& s = water_summary();
    if (!(effective_radius_um >= s.r_eff_um.front() && effective_radius_um <= s.r_eff_um.back())) {
      std::ostringstream msg;
      msg << "cloud_optics: water effective radius " << effective_radius_um << " um is outside the Mie table's "
          << s.r_eff_um.front() << "-" << s.r_eff_um.back() << " um";
      throw std::invalid_argument(msg.str());
    }
    optics.extinction_per_g_m3 = interpolate(s.r_eff_um, s.extinction_per_m, effective_radius_um);
    optics.albedo = interpolate(s.r_eff_um, s.albedo, effective_radius_um);
    optics.asymmetry = interpolate(s.r_eff_um, s.asymmetry, effective_radius_um);
    optics.phase = water_phase();
    return optics;
  }
  if (!(effective_radius_um > 0.0) || !std::isfinite(effective_radius_um)) {
    std::ostringstream msg;
    msg << "cloud_optics: ice effective radius " << effective_radius_um << " um must be finite and > 0";
    throw std::invalid_argument(msg.str());
  }
  // Geometric optics, Q_ext = 2: sigma_t = Q_ext * (projected area per
  // volume of ice) * (ice volume per m^3) = 2 * 3/(4 r_eff) * IWC/rho_ice
  // = 3 IWC / (2 rho_ice r_eff) (Foot 1988; Fu 1996 with D_e = 2 r_eff).
  // 1 g m^-3 = 1e-3 kg m^-3, r_eff in metres: m^-1.
  const double iwc_kg_m3 = 1e-3;
  optics.extinction_per_g_m3 = 3.0 * iwc_kg_m3 / (2.0 * kIceDensity_kg_m3 * effective_radius_um * 1e-6);
  optics.albedo = 1.0;  // ice absorbs almost nothing in the visible (k < 1e-8, Warren & Brandt 2008)
  optics.phase = ice_phase();
  optics.asymmetry = optics.phase.mean_cosine();
  return optics;
}

}  // namespace skyfarm
