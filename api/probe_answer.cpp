#include "api/probe_answer.h"

#include <algorithm>
#include <chrono>

#include "common/core/constants.h"
#include "common/geometry/ray.h"
#include "common/lut/lut_probe.h"
#include "common/render/radiance_probe.h"
#include "common/render/scene.h"

namespace skyfarm::api {

nlohmann::json answer_probe(const ProbeRequest& request, int threads) {
  const auto [lmin, lmax] = std::minmax_element(request.wavelengths_nm.begin(), request.wavelengths_nm.end());
  // The majorant grid must cover every asked wavelength; 1 nm margin.
  const Scene scene = Scene::from_specs(request.atmosphere, request.sun, request.location, request.time,
                                        *lmin - 0.5, *lmax + 0.5);
  std::vector<glm::dvec3> dirs;
  nlohmann::json dirs_json = nlohmann::json::array();
  for (const auto& d : request.directions) {
    dirs.push_back(direction_from_zenith_azimuth(d.zenith_deg * kDegToRad, d.azimuth_deg * kDegToRad));
    dirs_json.push_back({{"zenith_deg", d.zenith_deg}, {"azimuth_deg", d.azimuth_deg}});
  }
  const bool lut = request.method == Method::kLut;
  const auto t0 = std::chrono::steady_clock::now();
  nlohmann::json radiance, standard_error = nullptr;
  std::uint64_t nonfinite = 0;
  if (lut) {
    radiance = probe_radiance_lut(scene.atmosphere(), scene.sun(), scene.observer_altitude_m(), dirs,
                                  request.wavelengths_nm);
  } else {
    const ProbeResult r = probe_radiance(scene, dirs, request.wavelengths_nm, request.samples, request.seed, threads);
    radiance = r.radiance;
    standard_error = r.standard_error;
    nonfinite = r.counters.nonfinite;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {{"units", "W m-2 sr-1 nm-1"},
          {"wavelengths_nm", request.wavelengths_nm},
          {"directions", dirs_json},
          {"radiance", radiance},
          {"standard_error", standard_error},
          {"samples", lut ? nlohmann::json(nullptr) : nlohmann::json(request.samples)},
          {"seed", request.seed},
          {"method", lut ? "lut" : "path"},
          {"approximate", lut},
          {"sun", {{"zenith_deg", scene.sun().zenith_deg()}, {"azimuth_deg", scene.sun().azimuth_deg()}}},
          {"elapsed_s", seconds},
          {"nonfinite_paths", nonfinite}};
}

}  // namespace skyfarm::api
