#include "api/probe_answer.h"

#include <algorithm>

#include "common/core/constants.h"
#include "common/geometry/ray.h"
#include "common/lut/lut_probe.h"
#include "common/render/radiance_control.h"
#include "common/render/radiance_probe.h"
#include "common/render/render_plan.h"

namespace skyfarm::api {
namespace {

constexpr std::size_t kMaxUnits = kProbeDefaultMaxUnits;
constexpr std::size_t kMinUnits = 64;
constexpr std::size_t kUnitTextBudgetBytes = std::size_t{256} << 20;

nlohmann::json directions_json(const ProbeRequest& request) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& d : request.directions) out.push_back({{"zenith_deg", d.zenith_deg}, {"azimuth_deg", d.azimuth_deg}});
  return out;
}

nlohmann::json answer(const ProbeRequest& request, const Sun& sun, nlohmann::json radiance,
                      nlohmann::json standard_error, std::uint64_t nonfinite) {
  const bool lut = request.method == Method::kLut;
  return {{"units", "W m-2 sr-1 nm-1"},
          {"wavelengths_nm", request.wavelengths_nm},
          {"directions", directions_json(request)},
          {"radiance", std::move(radiance)},
          {"standard_error", std::move(standard_error)},
          {"samples", lut ? nlohmann::json(nullptr) : nlohmann::json(request.samples)},
          {"seed", request.seed},
          {"method", lut ? "lut" : "path"},
          {"approximate", lut},
          {"sun", {{"zenith_deg", sun.zenith_deg()}, {"azimuth_deg", sun.azimuth_deg()}}},
          {"nonfinite_paths", nonfinite}};
}

}  // namespace

Scene probe_scene(const ProbeRequest& request) {
  const auto [lmin, lmax] = std::minmax_element(request.wavelengths_nm.begin(), request.wavelengths_nm.end());
  // The majorant grid must cover every asked wavelength; 1 nm margin.
  return Scene::from_specs(request.atmosphere, request.sun, request.location, request.time, *lmin - 0.5,
                           *lmax + 0.5);
}

std::vector<glm::dvec3> probe_directions(const ProbeRequest& request) {
  std::vector<glm::dvec3> dirs;
  dirs.reserve(request.directions.size());
  for (const auto& d : request.directions)
    dirs.push_back(direction_from_zenith_azimuth(d.zenith_deg * kDegToRad, d.azimuth_deg * kDegToRad));
  return dirs;
}

ProbePlan probe_plan(const ProbeRequest& request) {
  const std::size_t text = std::max<std::size_t>(1, canonical_text(request).size());
  const std::size_t max_units = std::clamp(kUnitTextBudgetBytes / text, kMinUnits, kMaxUnits);
  return ProbePlan::make(request.directions.size() * request.wavelengths_nm.size(),
                         static_cast<std::uint64_t>(request.samples), max_units);
}

std::shared_ptr<const RadianceControl> probe_roulette_control(const ProbeRequest& request, const Scene& scene) {
  if (request.method != Method::kPath || !roulette_control_pays(scene.sun().zenith_deg())) return nullptr;
  return std::make_shared<const RadianceControl>(scene);
}

nlohmann::json path_probe_answer(const ProbeRequest& request, const ProbeResult& result) {
  const Sun sun = Sun::from_spec(request.sun, request.location, request.time);
  return answer(request, sun, result.radiance, result.standard_error, result.counters.nonfinite);
}

nlohmann::json answer_probe(const ProbeRequest& request, int threads) {
  const Scene scene = probe_scene(request);
  const std::vector<glm::dvec3> dirs = probe_directions(request);
  if (request.method == Method::kLut)
    return answer(request, scene.sun(),
                  probe_radiance_lut(scene.atmosphere(), scene.sun(), scene.observer_altitude_m(), dirs,
                                     request.wavelengths_nm),
                  nullptr, 0);
  const ProbeResult r = probe_radiance(scene, dirs, request.wavelengths_nm, probe_plan(request), request.seed, threads,
                                       probe_roulette_control(request, scene));
  return path_probe_answer(request, r);
}

}  // namespace skyfarm::api
