#include "api/probe_answer.h"

namespace skyfarm::api {
namespace {

nlohmann::json directions_json(const ProbeRequest& request) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& d : request.directions) out.push_back({{"zenith_deg", d.zenith_deg}, {"azimuth_deg", d.azimuth_deg}});
  return out;
}

}  // namespace

nlohmann::json probe_answer_json(const ProbeRequest& request, const ProbeAnswer& answer) {
  const bool lut = request.method == Method::kLut;
  return {{"units", "W m-2 sr-1 nm-1"},
          {"wavelengths_nm", request.wavelengths_nm},
          {"directions", directions_json(request)},
          {"radiance", answer.radiance},
          {"standard_error", answer.standard_error ? nlohmann::json(*answer.standard_error) : nlohmann::json(nullptr)},
          {"samples", lut ? nlohmann::json(nullptr) : nlohmann::json(request.samples)},
          {"seed", request.seed},
          {"method", lut ? "lut" : "path"},
          {"approximate", lut},
          {"sun", {{"zenith_deg", answer.sun_zenith_deg}, {"azimuth_deg", answer.sun_azimuth_deg}}},
          {"nonfinite_paths", answer.nonfinite_paths}};
}

}  // namespace skyfarm::api
