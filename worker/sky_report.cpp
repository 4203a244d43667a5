#include "worker/sky_report.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/atmosphere/atmosphere_builder.h"
#include "common/atmosphere/refraction_table.h"
#include "common/atmosphere/us76.h"
#include "common/core/constants.h"
#include "common/geometry/sphere_intersection.h"
#include "common/sun/solar_position.h"
#include "common/sun/sun.h"

namespace skyfarm {
namespace {

// Wavelengths at which optical depths are reported: the usual blue / green /
// red triple plus the request's range ends.
std::vector<double> report_wavelengths(const api::SpectralSpec& s) {
  std::vector<double> l{s.min_nm};
  for (double x : {400.0, 550.0, 700.0})
    if (x > s.min_nm && x < s.max_nm) l.push_back(x);
  l.push_back(s.max_nm);
  return l;
}

std::string fixed(double x, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}

std::string scientific(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

// Where the sun appears to the observer once the air bends its light: the
// ray-traced refraction of US76 (common/atmosphere/refraction_table.h) at
// 550 nm for the observer's altitude, next to the SPA's Bennett-based
// correction at the same altitude's US76 pressure and temperature.  The
// renderers still use the geometric position; this is a report.
nlohmann::json apparent_sun_report(const Atmosphere& atmosphere, double geometric_zenith_deg, double altitude_m) {
  constexpr double kWavelength_nm = 550.0;
  RefractionTable::Options options;
  options.wavelengths_nm = {kWavelength_nm};
  options.planet_radius_m = atmosphere.planet_radius_m();
  options.top_altitude_m = atmosphere.top_altitude_m();
  const RefractionTable table(altitude_m, options);
  const double geometric_elevation = 90.0 - geometric_zenith_deg;
  const double h = std::max(0.0, altitude_m);
  nlohmann::json a = {
      {"wavelength_nm", kWavelength_nm},
      {"model", "ray-traced US76, Ciddor refractive index"},
      {"geometric_elevation_deg", geometric_elevation},
      {"bennett_refraction_arcmin",
       60.0 * refraction_correction_deg(geometric_elevation, us76::pressure_Pa(h) / 100.0,
                                        us76::temperature_K(h) - 273.15)}};
  const auto apparent = table.apparent_elevation_deg(geometric_elevation, kWavelength_nm);
  a["visible"] = apparent.has_value();
  if (apparent) {
    a["apparent_elevation_deg"] = *apparent;
    a["apparent_zenith_deg"] = 90.0 - *apparent;
    a["refraction_arcmin"] = 60.0 * (*apparent - geometric_elevation);
  }
  return a;
}

}  // namespace

nlohmann::json sky_report(const api::RenderRequest& request) {
  const Atmosphere atmosphere = build_atmosphere(request.atmosphere);
  const Sun sun = Sun::from_spec(request.sun, request.location, request.time);
  nlohmann::json r;
  r["time_utc"] = request.time ? nlohmann::json(request.time->to_iso8601()) : nlohmann::json(nullptr);
  r["location"] = {{"latitude_deg", request.location.latitude_deg},
                   {"longitude_deg", request.location.longitude_deg},
                   {"altitude_m", request.location.altitude_m}};
  r["sun"] = {{"zenith_deg", sun.zenith_deg()},
              {"azimuth_deg", sun.azimuth_deg()},
              {"earth_sun_distance_au", sun.distance_au()},
              {"angular_radius_deg", request.sun.angular_radius_deg},
              {"source", (request.sun.zenith_deg ? "request" : "solar position algorithm")}};
  r["apparent_sun"] = apparent_sun_report(atmosphere, sun.zenith_deg(), request.location.altitude_m);

  // Vertical optical depth of each constituent, ground to top.
  const auto wavelengths = report_wavelengths(request.spectral);
  r["wavelengths_nm"] = wavelengths;
  nlohmann::json constituents = nlohmann::json::array();
  for (std::size_t i = 0; i < atmosphere.constituents().size(); ++i) {
    std::vector<double> tau;
    for (double l : wavelengths)
      tau.push_back(atmosphere.vertical_optical_depth(l, 0.0, atmosphere.top_altitude_m(), static_cast<int>(i)));
    constituents.push_back({{"name", atmosphere.constituents()[i].name}, {"vertical_optical_depth", tau}});
  }
  r["constituents"] = constituents;

  // Direct sun from the observer: slant optical depth and transmittance, or
  // the planet in the way.
  const Ray to_sun{{0.0, 0.0, atmosphere.planet_radius_m() + request.location.altitude_m}, sun.direction()};
  const bool blocked = ground_distance(to_sun, atmosphere.planet_radius_m()) >= 0.0;
  nlohmann::json direct = {{"blocked_by_planet", blocked}};
  if (!blocked) {
    std::vector<double> tau, T;
    for (double l : wavelengths) {
      tau.push_back(atmosphere.optical_depth(to_sun, 1e300, l));
      T.push_back(std::exp(-tau.back()));
    }
    direct["slant_optical_depth"] = tau;
    direct["transmittance"] = T;
  }
  r["direct_sun"] = direct;
  r["planet_radius_m"] = atmosphere.planet_radius_m();
  r["top_altitude_m"] = atmosphere.top_altitude_m();
  r["ground_albedo_550"] = atmosphere.ground().albedo(550.0);
  return r;
}

std::string format_sky_report(const nlohmann::json& r) {
  std::ostringstream o;
  o << "time (UTC)        " << (r["time_utc"].is_null() ? "(not given)" : r["time_utc"].get<std::string>()) << "\n";
  o << "location          lat " << r["location"]["latitude_deg"].get<double>() << " deg, lon "
    << r["location"]["longitude_deg"].get<double>() << " deg, altitude " << r["location"]["altitude_m"].get<double>()
    << " m\n";
  const auto& s = r["sun"];
  o << "sun               zenith " << fixed(s["zenith_deg"].get<double>(), 4) << " deg, azimuth "
    << fixed(s["azimuth_deg"].get<double>(), 4) << " deg (" << s["source"].get<std::string>() << ")\n";
  o << "                  Earth-Sun distance " << fixed(s["earth_sun_distance_au"].get<double>(), 6)
    << " AU, disk radius " << s["angular_radius_deg"].get<double>() << " deg\n";
  const auto& a = r["apparent_sun"];
  if (a["visible"].get<bool>())
    o << "apparent sun      elevation " << fixed(a["apparent_elevation_deg"].get<double>(), 4) << " deg, zenith "
      << fixed(a["apparent_zenith_deg"].get<double>(), 4) << " deg: refraction "
      << fixed(a["refraction_arcmin"].get<double>(), 2) << " arcmin at 550 nm (ray-traced US76; SPA/Bennett "
      << fixed(a["bennett_refraction_arcmin"].get<double>(), 2) << ")\n";
  else
    o << "apparent sun      below the apparent horizon even with refraction (550 nm, ray-traced US76)\n";
  o << "                  (a report only: renders use the geometric position)\n\n";
  o << "vertical optical depth, ground to top (" << r["top_altitude_m"].get<double>() / 1000.0 << " km)\n";
  o << "  constituent ";
  for (double l : r["wavelengths_nm"]) o << "  " << fixed(l, 1) << " nm";
  o << "\n";
  for (const auto& c : r["constituents"]) {
    std::string name = c["name"].get<std::string>();
    name.resize(12, ' ');
    o << "  " << name;
    for (double tau : c["vertical_optical_depth"]) {
      std::string cell = scientific(tau);
      cell.insert(0, cell.size() < 10 ? 10 - cell.size() : 0, ' ');
      o << "  " << cell;
    }
    o << "\n";
  }
  o << "\ndirect sun from the observer\n";
  const auto& d = r["direct_sun"];
  if (d["blocked_by_planet"].get<bool>()) {
    o << "  the sun is below the planet's horizon: no direct light\n";
  } else {
    o << "  slant optical depth ";
    for (double tau : d["slant_optical_depth"]) o << "  " << scientific(tau);
    o << "\n  transmittance       ";
    for (double T : d["transmittance"]) o << "  " << scientific(T);
    o << "\n";
  }
  return o.str();
}

}  // namespace skyfarm
