// The radiance probe (CLI `skyfarm-worker probe`, HTTP
// `POST /v1/sky/radiance`): the render request's location, time, sun and
// atmosphere plus directions and wavelengths.  Field by field rules:
// docs/request-schema.md.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/field_error.h"
#include "api/json_fields.h"
#include "common/atmosphere/atmosphere_spec.h"
#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm::api {

// One entry of "directions": zenith 0 = straight up, azimuth clockwise from north.
struct ProbeDirection {
  double zenith_deg = 0.0;
  double azimuth_deg = 0.0;
};

// A validated probe request, every default filled in.
struct ProbeRequest {
  Location location;
  std::optional<UtcInstant> time;
  std::optional<std::string> time_text;  // "time" as the client wrote it
  SunSpec sun;
  AtmosphereSpec atmosphere;
  std::vector<ProbeDirection> directions;  // 1..10000
  std::vector<double> wavelengths_nm;      // 1..10000, in [230, 2500]
  int samples = 4096;                      // per direction and wavelength
  std::uint64_t seed = 1;
  Method method = Method::kPath;
};

// Parses and validates a probe body.  Throws ValidationError listing every
// invalid field; no other exception escapes, whatever the input.
ProbeRequest parse_probe_request(std::string_view json_text);
ProbeRequest parse_probe_request(const nlohmann::json& body);
inline ProbeRequest parse_probe_request(const std::string& json_text) {
  return parse_probe_request(std::string_view(json_text));
}
inline ProbeRequest parse_probe_request(const char* json_text) {
  return parse_probe_request(std::string_view(json_text));
}

// Canonical form, as for the render request (docs/request-schema.md).
nlohmann::json to_canonical_json(const ProbeRequest& request);
std::string canonical_text(const ProbeRequest& request);

}  // namespace skyfarm::api
