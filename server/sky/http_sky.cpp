#include "server/sky/http_sky.h"

#include <httplib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <set>
#include <string_view>
#include <vector>

#include <glm/geometric.hpp>

#include "api/json_fields.h"
#include "api/probe_request.h"
#include "common/core/constants.h"
#include "common/sun/solar_position.h"
#include "server/http/http_checks.h"
#include "server/http/http_problem.h"

namespace skyfarm::server {
namespace {

using api::FieldError;
using Json = nlohmann::json;

constexpr double kDefaultMinNm = 360.0;
constexpr double kDefaultMaxNm = 830.0;
constexpr double kBaseRangeNm = kDefaultMaxNm - kDefaultMinNm;  // base_spectral_bins cover this
constexpr int kMinBins = 4;
constexpr int kMaxBins = 96;

constexpr std::string_view kCommonParams[] = {"lat",     "lon",     "altitude", "time",    "sun_zenith",
                                              "sun_azimuth", "preset", "ozone_du", "aod",  "aerosol",
                                              "albedo",  "min_nm",  "max_nm", "refraction"};
constexpr std::string_view kLookupParams[] = {"view_zenith", "view_azimuth"};
constexpr std::string_view kEnvmapParams[] = {"width", "sun", "layout", "color_space", "units"};

// The probe's field paths -> the query parameters they came from.
struct PathName {
  std::string_view path, name;
};
constexpr PathName kFieldNames[] = {
    {"location.latitude_deg", "lat"},
    {"location.longitude_deg", "lon"},
    {"location.altitude_m", "altitude"},
    {"time", "time"},
    {"sun.zenith_deg", "sun_zenith"},
    {"sun.azimuth_deg", "sun_azimuth"},
    {"atmosphere.preset", "preset"},
    {"atmosphere.ozone_du", "ozone_du"},
    {"atmosphere.aerosol.optical_depth_550", "aod"},
    {"atmosphere.aerosol", "aod"},
    {"atmosphere.ground_albedo", "albedo"},
    {"atmosphere.refraction", "refraction"},
    {"directions[0].zenith_deg", "view_zenith"},
    {"directions[0].azimuth_deg", "view_azimuth"},
    {"wavelengths_nm[0]", "min_nm"},
    {"wavelengths_nm[1]", "max_nm"},
};

std::string query_name_of(const std::string& path) {
  for (const auto& m : kFieldNames)
    if (m.path == path) return std::string(m.name);
  return path;  // not one of ours: keep the probe's name rather than lose it
}

// The probe's rules name JSON fields ("required unless sun.zenith_deg and
// sun.azimuth_deg are given"): say the query parameters instead.
std::string query_rule(std::string rule) {
  for (const auto& m : kFieldNames) {
    if (m.path.find('.') == std::string_view::npos) continue;
    for (std::size_t at; (at = rule.find(m.path)) != std::string::npos;) rule.replace(at, m.path.size(), m.name);
  }
  return rule;
}

// "text" (appended piecewise: GCC 12 warns falsely on "\"" + s + "\"").
std::string quoted_text(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out.push_back('"');
  out.append(text);
  out.push_back('"');
  return out;
}

std::string quote_value(std::string_view text) { return quoted_text(printable_excerpt(text)); }

// A finite decimal number, all of the text (no spaces, no sign '+', no hex).
std::optional<double> parse_number(std::string_view text) {
  if (text.empty()) return std::nullopt;
  for (char c : text)
    if (!((c >= '0' && c <= '9') || c == '-' || c == '.' || c == 'e' || c == 'E' || c == '+')) return std::nullopt;
  double x = 0.0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), x, std::chars_format::general);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || !std::isfinite(x)) return std::nullopt;
  return x;
}

int bins_for(double min_nm, double max_nm, int base_bins) {
  const double n = std::round(double(std::max(1, base_bins)) * (max_nm - min_nm) / kBaseRangeNm);
  return static_cast<int>(std::clamp(n, double(kMinBins), double(kMaxBins)));
}

// skyfarm:layout, the mapping and its axes in words.
constexpr const char* kLatlongLayoutText = "latlong: centre = north (azimuth 0), right = east, top = zenith";
constexpr const char* kEqualAreaLayoutText =
    "equal_area: Clarberg octahedral, as pbrt-v4 imagemap; pixel (x, y) -> u = (x + 1/2) / width, "
    "v = (y + 1/2) / width (y down) -> direction (x, y, z) = (east, north, zenith): centre = zenith, "
    "below it north, right of it east, corners = nadir; every pixel 4 pi / width^2 sr";

const char* sun_mode_name(EnvmapSun mode) {
  switch (mode) {
    case EnvmapSun::kNone: return "none";
    case EnvmapSun::kSeparate: return "separate";
    case EnvmapSun::kDisk: break;
  }
  return "disk";
}

// Reads the parameters into a probe body (for the shared validation) and
// records what the probe cannot check.
class QueryReader {
 public:
  QueryReader(const QueryParams& params, SkyRoute route) : params_(params) {
    std::set<std::string_view> allowed(std::begin(kCommonParams), std::end(kCommonParams));
    if (route == SkyRoute::kLookup) allowed.insert(std::begin(kLookupParams), std::end(kLookupParams));
    else allowed.insert(std::begin(kEnvmapParams), std::end(kEnvmapParams));
    std::string list;
    for (const auto& name : allowed_order(route)) list += (list.empty() ? "" : ", ") + std::string(name);
    for (auto it = params.begin(); it != params.end(); it = params.upper_bound(it->first)) {
      if (!allowed.count(it->first))
        errors_.push_back({printable_excerpt(it->first, 64), "unknown parameter (allowed: " + list + ")", ""});
      else if (const std::size_t n = params.count(it->first); n > 1)
        errors_.push_back({it->first, "must be given once", std::to_string(n) + " values"});
    }
  }

  // The text of a parameter given once, or nullopt (absent, or repeated: reported).
  std::optional<std::string> text(std::string_view name) const {
    const auto range = params_.equal_range(std::string(name));
    if (range.first == range.second || std::next(range.first) != range.second) return std::nullopt;
    return range.first->second;
  }

  std::optional<double> number(std::string_view name) {
    const auto t = text(name);
    if (!t) return std::nullopt;
    const auto x = parse_number(*t);
    if (!x) errors_.push_back({std::string(name), "must be a finite decimal number", quote_value(*t)});
    return x;
  }

  // A number into the probe body at `object[key]` when given and readable.
  void number_into(std::string_view name, Json& object, const char* key) {
    if (const auto x = number(name)) object[key] = *x;
  }

  void error(std::string name, std::string rule, std::string value = {}) {
    errors_.push_back({std::move(name), std::move(rule), std::move(value)});
  }
  std::vector<FieldError>& errors() { return errors_; }

 private:
  static std::vector<std::string_view> allowed_order(SkyRoute route) {
    std::vector<std::string_view> v(std::begin(kCommonParams), std::end(kCommonParams));
    if (route == SkyRoute::kLookup) v.insert(v.end(), std::begin(kLookupParams), std::end(kLookupParams));
    else v.insert(v.end(), std::begin(kEnvmapParams), std::end(kEnvmapParams));
    return v;
  }

  const QueryParams& params_;
  std::vector<FieldError> errors_;
};

Json xyz_json(const Xyz& c) { return {{"X", c.x}, {"Y", c.y}, {"Z", c.z}}; }

// Sends `body` with a strong ETag and Cache-Control, or 304 when the client
// holds it already.
bool not_modified(const httplib::Request& req, httplib::Response& res, const std::string& etag,
                  const char* cache_control) {
  res.set_header("ETag", etag);
  res.set_header("Cache-Control", cache_control);
  if (!if_none_match_matches(req.get_header_value("If-None-Match"), etag)) return false;
  res.status = 304;
  return true;
}

}  // namespace

SkyQuery parse_sky_query(const QueryParams& params, SkyRoute route, int base_spectral_bins) {
  QueryReader q(params, route);
  SkyQuery out;

  // The probe body: the shared validation of location, time, sun, atmosphere.
  Json body = {{"method", "lut"}};
  Json location = Json::object();
  q.number_into("lat", location, "latitude_deg");
  q.number_into("lon", location, "longitude_deg");
  q.number_into("altitude", location, "altitude_m");
  body["location"] = location;
  if (auto t = q.text("time")) {
    // An unencoded '+' of the offset arrives as a space ("...T09:30:00 09:00"):
    // take it for the '+' the client meant.
    if (t->size() > 6 && (*t)[t->size() - 6] == ' ' && (*t)[t->size() - 3] == ':') (*t)[t->size() - 6] = '+';
    body["time"] = *t;
  }
  // An unreadable angle is reported here; a placeholder keeps the probe from
  // also asking for it (or for a time).
  Json sun = Json::object();
  for (auto [name, key] : {std::pair{"sun_zenith", "zenith_deg"}, std::pair{"sun_azimuth", "azimuth_deg"}})
    if (q.text(name)) sun[key] = q.number(name).value_or(0.0);
  body["sun"] = sun;

  Json atmosphere = Json::object();
  if (const auto preset = q.text("preset")) {
    if (*preset == "earth" || *preset == "earth_clear") atmosphere["preset"] = *preset;
    else q.error("preset", "must be one of earth, earth_clear", quote_value(*preset));
  }
  q.number_into("ozone_du", atmosphere, "ozone_du");
  const auto aerosol = q.text("aerosol");
  if (aerosol && *aerosol != "none")
    q.error("aerosol", "must be none (or leave it out and give aod)", quote_value(*aerosol));
  if (const auto aod = q.number("aod")) {
    if (aerosol && *aerosol == "none") q.error("aod", "not allowed with aerosol=none", exact_decimal(*aod));
    else atmosphere["aerosol"] = {{"optical_depth_550", *aod}};
  }
  if (aerosol && *aerosol == "none") atmosphere["aerosol"] = nullptr;
  q.number_into("albedo", atmosphere, "ground_albedo");
  if (const auto refraction = q.text("refraction")) {
    if (*refraction == "true" || *refraction == "false") atmosphere["refraction"] = *refraction == "true";
    else q.error("refraction", "must be true or false", quote_value(*refraction));
  }
  body["atmosphere"] = atmosphere;

  Json direction = {{"zenith_deg", 0.0}, {"azimuth_deg", 0.0}};
  if (route == SkyRoute::kLookup) {
    for (auto [name, key] : {std::pair{"view_zenith", "zenith_deg"}, std::pair{"view_azimuth", "azimuth_deg"}}) {
      if (!q.text(name) && !params.count(name)) q.error(name, "required");
      q.number_into(name, direction, key);
    }
  }
  body["directions"] = Json::array({direction});
  const auto min_nm = q.number("min_nm"), max_nm = q.number("max_nm");
  body["wavelengths_nm"] = Json::array({min_nm.value_or(kDefaultMinNm), max_nm.value_or(kDefaultMaxNm)});

  if (route == SkyRoute::kEnvmap) {
    if (const auto w = q.text("width")) {
      const auto value = parse_decimal(*w, 1u << 30);
      if (!value || *value < kEnvmapMinWidth || *value > kEnvmapMaxWidth || *value % 2 != 0)
        q.error("width",
                "must be an even integer in [" + std::to_string(kEnvmapMinWidth) + ", " +
                    std::to_string(kEnvmapMaxWidth) + "]",
                quote_value(*w));
      else
        out.width = static_cast<int>(*value);
    }
    if (const auto s = q.text("sun")) {
      if (*s == "disk") out.sun_mode = EnvmapSun::kDisk;
      else if (*s == "none") out.sun_mode = EnvmapSun::kNone;
      else if (*s == "separate") out.sun_mode = EnvmapSun::kSeparate;
      else q.error("sun", "must be one of disk, none, separate", quote_value(*s));
    }
    if (const auto l = q.text("layout")) {
      if (*l == "latlong") out.layout = EnvmapLayout::kLatlong;
      else if (*l == "equal_area") out.layout = EnvmapLayout::kEqualArea;
      else q.error("layout", "must be one of latlong, equal_area", quote_value(*l));
    }
    // A square map of width^2 pixels: bounded like the lat-long ones' pixel count.
    if (out.layout == EnvmapLayout::kEqualArea && out.width > kEnvmapMaxWidthEqualArea)
      q.error("width", "must be at most " + std::to_string(kEnvmapMaxWidthEqualArea) + " with layout=equal_area",
              std::to_string(out.width));
    // The names of the render request's output.color_space / output.units.
    auto names_of = [](const auto& names) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + std::string(n.first);
      return list;
    };
    if (const auto c = q.text("color_space")) {
      if (const auto v = color_space_named(*c)) out.color_space = *v;
      else q.error("color_space", "must be one of " + names_of(kColorSpaceNames), quote_value(*c));
    }
    if (const auto u = q.text("units")) {
      if (const auto v = units_named(*u)) out.units = *v;
      else q.error("units", "must be one of " + names_of(kRadiometricUnitsNames), quote_value(*u));
    }
  }

  std::optional<api::ProbeRequest> probe;
  try {
    probe = api::parse_probe_request(body);
  } catch (const api::ValidationError& e) {
    for (const FieldError& f : e.errors()) {
      const std::string name = query_name_of(f.path);
      // One error per parameter: ours (unreadable number, ...) come first.
      const bool seen = std::any_of(q.errors().begin(), q.errors().end(),
                                    [&](const FieldError& g) { return g.path == name; });
      if (seen) continue;
      // A number is quoted as the client wrote it ("95", not the parser's "95.0").
      const auto raw = name == "time" ? std::nullopt : q.text(name);
      q.error(name, query_rule(f.rule), raw ? printable_excerpt(*raw) : f.value);
    }
  }
  const bool range_named = std::any_of(q.errors().begin(), q.errors().end(), [](const FieldError& f) {
    return f.path == "min_nm" || f.path == "max_nm";
  });
  if (!range_named && min_nm.value_or(kDefaultMinNm) >= max_nm.value_or(kDefaultMaxNm))
    q.error(max_nm ? "max_nm" : "min_nm", "max_nm must be greater than min_nm",
            exact_decimal(min_nm.value_or(kDefaultMinNm)) + " >= " + exact_decimal(max_nm.value_or(kDefaultMaxNm)));
  if (!q.errors().empty()) throw api::ValidationError(std::move(q.errors()));
  if (!probe) throw api::ValidationError({FieldError{"", "could not be read", ""}});

  out.location = probe->location;
  out.time = probe->time;
  out.sun_zenith_deg = probe->sun.zenith_deg;
  out.sun_azimuth_deg = probe->sun.azimuth_deg;
  out.atmosphere = probe->atmosphere;
  out.min_nm = min_nm.value_or(kDefaultMinNm);
  out.max_nm = max_nm.value_or(kDefaultMaxNm);
  out.view_zenith_deg = probe->directions.at(0).zenith_deg;
  out.view_azimuth_deg = probe->directions.at(0).azimuth_deg;
  // Above the top every pixel is a ray march (~3 s for 1024 x 512 on 2 cores).
  if (route == SkyRoute::kEnvmap && out.location.altitude_m > out.atmosphere.top_altitude_m &&
      out.width > kEnvmapMaxWidthAboveAtmosphere)
    throw api::ValidationError({FieldError{
        "width",
        "must be at most " + std::to_string(kEnvmapMaxWidthAboveAtmosphere) +
            " for an observer above the atmosphere (altitude > " + exact_decimal(out.atmosphere.top_altitude_m) +
            " m): every pixel is a ray march there",
        std::to_string(out.width)}});

  // The sun: the angles given, else the position at `time`; the irradiance
  // scaled to the Earth-Sun distance of `time` (1 AU without one), as
  // Sun::from_spec does for renders.
  SkyTableParams& t = out.table;
  t.atmosphere = out.atmosphere;
  t.sun_angular_radius_deg = probe->sun.angular_radius_deg;
  if (out.time) {
    const SolarPosition p = solar_position(out.location, *out.time);
    t.sun_zenith_deg = p.zenith_deg;
    t.sun_azimuth_deg = p.azimuth_deg;
    t.sun_distance_au = p.earth_sun_distance_au;
  }
  if (out.sun_zenith_deg && out.sun_azimuth_deg) {
    t.sun_zenith_deg = *out.sun_zenith_deg;
    t.sun_azimuth_deg = api::canonical_azimuth(*out.sun_azimuth_deg);
  }
  t.altitude_m = out.location.altitude_m;
  t.min_nm = out.min_nm;
  t.max_nm = out.max_nm;
  t.resolution.spectral_bins = bins_for(out.min_nm, out.max_nm, base_spectral_bins);
  return out;
}

Json SkyQuery::canonical_json(SkyRoute route) const {
  std::optional<double> azimuth = sun_azimuth_deg;
  if (azimuth) *azimuth = api::canonical_azimuth(*azimuth);
  Json j = {{"method", "lut"},
            {"location", api::location_json(location)},
            {"time", api::time_json(time)},
            {"sun", {{"zenith_deg", api::optional_number_json(sun_zenith_deg)},
                     {"azimuth_deg", api::optional_number_json(azimuth)}}},
            {"atmosphere", api::atmosphere_json(atmosphere)},
            {"spectral", {{"min_nm", api::canonical_number(min_nm)}, {"max_nm", api::canonical_number(max_nm)},
                          {"bins", table.resolution.spectral_bins}}}};
  if (route == SkyRoute::kLookup) {
    j["view"] = {{"zenith_deg", api::canonical_number(view_zenith_deg)},
                 {"azimuth_deg", api::canonical_azimuth(view_azimuth_deg)}};
  } else {
    j["width"] = width;
    j["sun_mode"] = sun_mode_name(sun_mode);
    if (layout == EnvmapLayout::kEqualArea) j["layout"] = "equal_area";
    // Only when not the default: the maps of before keep their key and ETag.
    if (color_space != ColorSpace::kLinRec709) j["color_space"] = std::string(name_of(color_space));
    if (units != RadiometricUnits::kCdM2) j["units"] = std::string(name_of(units));
  }
  return j;
}

// --- Handlers -------------------------------------------------------------------

SkyHttp::SkyHttp(std::shared_ptr<SkyService> service, bool private_cache)
    : service_(std::move(service)),
      cache_control_(private_cache ? "private, max-age=3600" : "public, max-age=3600") {}

void SkyHttp::lookup(const httplib::Request& req, httplib::Response& res) const {
  const SkyQuery q = parse_sky_query(req.params, SkyRoute::kLookup, service_->options().resolution.spectral_bins);
  const std::shared_ptr<const SkyTable> table = service_->table(q.table);
  const SpectralGrid& grid = table->sky.grid();
  const std::size_t B = static_cast<std::size_t>(grid.size());
  const double z = q.view_zenith_deg * kDegToRad, a = q.view_azimuth_deg * kDegToRad;
  const glm::dvec3 dir(std::sin(z) * std::sin(a), std::sin(z) * std::cos(a), std::cos(z));
  std::array<double, 512> L{};
  table->sky.radiance(dir, std::span<double>(L.data(), B), true);
  const Xyz xyz = table->xyz(std::span<const double>(L.data(), B));
  const Rgb rgb = xyz_to_linear_srgb(xyz);

  Json wavelengths = Json::array(), radiance = Json::array();
  for (std::size_t b = 0; b < B; ++b) {
    wavelengths.push_back(grid.centre_nm(static_cast<int>(b)));
    radiance.push_back(L[b]);
  }
  const Json answer = {{"method", "lut"},
                       {"approximate", true},
                       {"units", "W m-2 sr-1 nm-1"},
                       {"wavelengths_nm", std::move(wavelengths)},
                       {"bin_width_nm", grid.width_nm()},
                       {"spectral_radiance", std::move(radiance)},
                       {"xyz", xyz_json(xyz)},
                       {"linear_srgb", {{"r", rgb.r}, {"g", rgb.g}, {"b", rgb.b}}},
                       {"luminance_cd_m2", xyz.y},
                       {"sun", {{"zenith_deg", q.table.sun_zenith_deg}, {"azimuth_deg", q.table.sun_azimuth_deg}}},
                       {"view",
                        {{"zenith_deg", q.view_zenith_deg},
                         {"azimuth_deg", api::canonical_azimuth(q.view_azimuth_deg)}}},
                       {"in_sun_disk", table->sky.sees_sun_disk(glm::normalize(dir))},
                       {"altitude_m", q.location.altitude_m}};
  std::string body = dump_json(answer);
  if (not_modified(req, res, quoted_text(text_hash(body)), cache_control_)) return;
  res.status = 200;
  res.set_content(std::move(body), "application/json");
}

void SkyHttp::envmap(const httplib::Request& req, httplib::Response& res) const {
  const SkyQuery q = parse_sky_query(req.params, SkyRoute::kEnvmap, service_->options().resolution.spectral_bins);
  const Json canonical = q.canonical_json(SkyRoute::kEnvmap);
  const std::string key = canonical.dump();
  SkyService& service = *service_;
  const std::shared_ptr<const EnvmapFile> file = service.envmap(key, [&] {
    const std::shared_ptr<const SkyTable> table = service.table(q.table);
    const bool latlong = q.layout == EnvmapLayout::kLatlong;
    Image image = latlong ? render_envmap(*table, q.width, q.sun_mode, service.options().envmap_threads)
                          : render_envmap_equal_area(*table, q.width, q.sun_mode, service.options().envmap_threads);
    namespace mk = metadata_key;
    image.set_metadata(mk::kMethod, std::string("lut"));
    image.set_metadata(mk::kApproximate, std::string("true"));
    image.set_metadata(mk::kRequest, key);
    image.set_metadata(mk::kSunZenithDeg, q.table.sun_zenith_deg);
    image.set_metadata(mk::kSunAzimuthDeg, q.table.sun_azimuth_deg);
    image.set_metadata(mk::kEarthSunDistanceAu, q.table.sun_distance_au);
    image.set_metadata(mk::kSunEarthDistanceAuDeprecated, q.table.sun_distance_au);
    image.set_metadata(mk::kSunAngularRadiusDeg, q.table.sun_angular_radius_deg);
    image.set_metadata(mk::kSunMode, std::string(sun_mode_name(q.sun_mode)));
    image.set_metadata(mk::kWavelengthMinNm, q.min_nm);
    image.set_metadata(mk::kWavelengthMaxNm, q.max_nm);
    image.set_metadata(mk::kObserverAltitudeM, q.location.altitude_m);
    image.set_metadata(mk::kLayout, std::string(latlong ? kLatlongLayoutText : kEqualAreaLayoutText));
    if (q.sun_mode == EnvmapSun::kSeparate) {
      const SunDiskSummary disk = sun_disk_summary(*table);
      image.set_metadata(mk::kSunDiskX, disk.xyz.x);
      image.set_metadata(mk::kSunDiskY, disk.xyz.y);
      image.set_metadata(mk::kSunDiskZ, disk.xyz.z);
      image.set_metadata(mk::kSunDiskR, disk.rgb.r);
      image.set_metadata(mk::kSunDiskG, disk.rgb.g);
      image.set_metadata(mk::kSunDiskB, disk.rgb.b);
      image.set_metadata(mk::kSunDiskSolidAngleSr, disk.solid_angle_sr);
      image.set_metadata(mk::kSunDiskIlluminanceLux, disk.illuminance_lux);
      const glm::dvec3& d = table->sun.direction();
      image.set_metadata(mk::kSunDirection, exact_decimal(d.x) + "," + exact_decimal(d.y) + "," + exact_decimal(d.z));
    }
    return encode_envmap_exr(image, latlong, q.color_space, q.units);
  });
  if (not_modified(req, res, file->etag, cache_control_)) return;
  res.status = 200;
  res.set_header("Content-Disposition", "inline; filename=\"sky.exr\"");
  res.set_content_provider(file->bytes.size(), "image/x-exr",
                           [file](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                             const std::size_t n = std::min(length, file->bytes.size() - offset);
                             return sink.write(file->bytes.data() + offset, n);
                           });
}

}  // namespace skyfarm::server
