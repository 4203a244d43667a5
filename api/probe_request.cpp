#include "api/probe_request.h"

#include <tuple>

namespace skyfarm::api {
namespace {

constexpr std::size_t kMaxDirections = 10000;
constexpr std::size_t kMaxWavelengths = 10000;
constexpr int kMaxSamples = 1000000000;  // per direction and wavelength (the server caps the whole probe too)

// --- "directions" (required): 1..10000 {zenith_deg, azimuth_deg}, both required.
void read_directions(const Fields& top, std::vector<ProbeDirection>& out) {
  Errors& e = top.errors();
  const std::string path = top.path_of("directions");
  const Json* v = top.find("directions");
  if (!v) {
    e.add(path, "required");
    return;
  }
  if (!expect_array(*v, path, 1, kMaxDirections, e)) return;
  out.reserve(v->size());
  for (std::size_t i = 0; i < v->size(); ++i) {
    const std::string p = index_path(path, i);
    if (!expect_object((*v)[i], p, e)) continue;
    Fields f((*v)[i], p, e);
    f.allow_only({"zenith_deg", "azimuth_deg"});
    ProbeDirection d;
    for (auto [name, range, value] : {std::tuple{"zenith_deg", Range::closed(0, 180), &d.zenith_deg},
                                      std::tuple{"azimuth_deg", Range::closed(0, 360), &d.azimuth_deg}}) {
      if (!f.find(name)) e.add(f.path_of(name), "required");
      else f.number(name, range, *value);
    }
    out.push_back(d);
  }
}

// --- "wavelengths_nm" (required): 1..10000 numbers in [230, 2500], any order.
void read_wavelengths(const Fields& top, std::vector<double>& out) {
  const Json* v = top.find("wavelengths_nm");
  if (!v) {
    top.errors().add(top.path_of("wavelengths_nm"), "required");
    return;
  }
  const ArrayRule rule{1, kMaxWavelengths, Range::closed(kMinSpectralNm, kMaxSpectralNm), false};
  if (auto w = read_number_array(*v, top.path_of("wavelengths_nm"), rule, top.errors())) out = std::move(*w);
}

// --- The whole probe.
ProbeRequest read_probe_request(const Json& body, Errors& e) {
  if (!body.is_object()) throw ValidationError({FieldError{"", "must be a JSON object", value_text(body)}});
  Fields top(body, "", e);
  top.allow_only({"location", "time", "sun", "atmosphere", "directions", "wavelengths_nm", "samples", "seed",
                  "method"});
  ProbeRequest r;
  read_location(top, r.location);
  read_time(top, r.time, r.time_text);
  read_sun(top, r.sun);
  require_time_or_sun(top);
  read_atmosphere(top, r.atmosphere);
  read_directions(top, r.directions);
  read_wavelengths(top, r.wavelengths_nm);
  top.integer("samples", 1, kMaxSamples, r.samples);
  read_seed(top, r.seed);
  read_method(top, r.method);
  e.throw_if_any();
  return r;
}

}  // namespace

ProbeRequest parse_probe_request(std::string_view json_text) {
  return guarded([&] {
    Errors errors;
    const Json body = parse_json_object(json_text, errors);
    return read_probe_request(body, errors);
  });
}

ProbeRequest parse_probe_request(const nlohmann::json& body) {
  return guarded([&] {
    Errors errors;
    return read_probe_request(body, errors);
  });
}

nlohmann::json to_canonical_json(const ProbeRequest& r) {
  Json directions = Json::array();
  for (const auto& d : r.directions)
    directions.push_back(
        {{"zenith_deg", canonical_number(d.zenith_deg)}, {"azimuth_deg", canonical_azimuth(d.azimuth_deg)}});
  Json wavelengths = Json::array();
  for (double w : r.wavelengths_nm) wavelengths.push_back(canonical_number(w));
  return {{"location", location_json(r.location)},
          {"time", time_json(r.time)},
          {"sun", sun_json(r.sun)},
          {"atmosphere", atmosphere_json(r.atmosphere)},
          {"directions", directions},
          {"wavelengths_nm", wavelengths},
          {"samples", r.samples},
          {"seed", r.seed},
          {"method", std::string(name_of(kMethods, r.method))}};
}

std::string canonical_text(const ProbeRequest& request) { return to_canonical_json(request).dump(); }

}  // namespace skyfarm::api
