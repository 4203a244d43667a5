// The cached sky look-ups of the HTTP API:
//
//   GET /v1/sky              radiance in one direction (JSON)
//   GET /v1/sky/envmap.exr   a lat-long environment map (OpenEXR)
//
// Query parameters (all numbers decimal, angles in degrees; each at most once):
//   lat, lon        observer latitude [-90, 90] (+north) and longitude
//                   [-180, 180] (+east), default 0, 0
//   altitude        observer altitude above the ground, m, [0, 1e8], default 0
//   time            ISO 8601 with a UTC offset (years 1800-2200); places the
//                   sun (NREL SPA) and scales its irradiance by 1/R^2.  A '+'
//                   sent unencoded arrives as a space: " hh:mm" at the end is
//                   read as "+hh:mm"
//   sun_zenith, sun_azimuth
//                   the sun's position ([0, 180], [0, 360], azimuth clockwise
//                   from north); both or neither; they replace the position
//                   computed from `time`.  `time` or both angles are required.
//   preset          earth (default: US76 air, ozone, aerosols AOD 0.1) |
//                   earth_clear (no aerosols unless `aod` is given)
//   ozone_du        total ozone column, Dobson units, [0, 1000], default 300
//   aod             aerosol optical depth at 550 nm, [0, 10], default 0.1
//   aerosol         `none`: no aerosols (not with `aod`)
//   albedo          Lambertian ground albedo, [0, 1], default 0.3
//   min_nm, max_nm  wavelength range, [230, 2500], min < max, default 360, 830;
//                   split into equal bins (16 over 360-830 nm, about 29 nm
//                   each, the same width for other ranges, 4 to 96 bins)
//   /v1/sky only:   view_zenith [0, 180] and view_azimuth [0, 360], required
//   envmap only:    width, even, [8, 8192], default 1024 (height = width / 2);
//                   at most 1024 for an observer above the atmosphere's top
//                   (100 km), where every pixel is a ray march (~3 s at 1024);
//                   sun = disk (default) | none | separate;
//                   layout = latlong (default) | equal_area: a width x width
//                   square in the equal-area octahedral mapping of pbrt-v4's
//                   `imagemap` infinite light (sky_service.h), width at most
//                   4096;
//                   color_space = lin_rec709 (default) | acescg | aces2065-1
//                   | cie_xyz and units = cd_m2 (default) | relative |
//                   w_m2_sr, as the render request's output.color_space and
//                   output.units (common/image/color_management.h; relative
//                   meters the map's own median luminance)
// Anything else is a 400 naming the unknown parameter; every invalid value
// is a 400 problem whose errors[].field is the query parameter's name.
//
// /v1/sky answers
//   {"method": "lut", "approximate": true, "units": "W m-2 sr-1 nm-1",
//    "wavelengths_nm": [bin centres], "bin_width_nm": w,
//    "spectral_radiance": [per bin], "xyz": {"X", "Y", "Z"},
//    "linear_srgb": {"r", "g", "b"}, "luminance_cd_m2": Y,
//    "sun": {"zenith_deg", "azimuth_deg"}, "view": {"zenith_deg", "azimuth_deg"},
//    "in_sun_disk": bool, "altitude_m": m}
// with the sun disk included when the view direction is inside it; XYZ and
// linear Rec.709 (D65) are absolute (Y in cd/m^2) over the part of the range
// inside 360-830 nm.
//
// /v1/sky/envmap.exr answers a FLOAT, PIZ (lossless) OpenEXR, width x width/2, the
// lat-long layout of the equirectangular renders (centre = north, right =
// east, top = zenith; `envmap` attribute LATLONG), linear Rec.709 in cd/m^2
// (whiteLuminance 1), with skyfarm:* attributes: method "lut", approximate
// "true", sun_zenith_deg, sun_azimuth_deg, earth_sun_distance_au (and
// sun_earth_distance_au, its deprecated alias), sun_angular_radius_deg,
// sun_mode, wavelength_min_nm, wavelength_max_nm, observer_altitude_m,
// request (the canonical parameters as JSON), software_version, layout (the
// mapping and its axes, in words; docs/exr-metadata.md).  With
// layout=equal_area the image is width x width, has no `envmap` attribute
// (OpenEXR names only latlong and cube maps) and skyfarm:layout begins
// "equal_area".  sun =
//   disk       the disk in the pixels, integrated over each pixel (its energy
//              is exact at any width; sky_service.h)
//   none       no disk
//   separate   no disk in the pixels; the disk as attributes instead:
//              sun_disk_X/_Y/_Z and sun_disk_R/_G/_B (its radiance averaged
//              over the disk, transmittance included, cd/m^2),
//              sun_disk_solid_angle_sr, sun_disk_illuminance_lux (normal
//              illuminance from the disk), sun_direction ("x,y,z" in the
//              observer frame: x east, y north, z up) - what a renderer needs
//              for a distant light.  These stay linear Rec.709 / XYZ in
//              cd/m^2 whatever color_space and units say; skyfarm:units_scale
//              converts them.
//
// Both: strong ETag (a hash of the body), If-None-Match -> 304, and
// Cache-Control "public, max-age=3600" ("private, max-age=3600" when the API
// needs a token).  The answer is a function of the query alone (the time is a
// parameter, never "now"), so time-dependent requests cache like the rest;
// the hour bounds how long a client keeps an answer across a server upgrade.
#pragma once
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "common/atmosphere/atmosphere_spec.h"
#include "common/image/color_management.h"
#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"
#include "server/sky/sky_service.h"

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace skyfarm::server {

// httplib::Params.
using QueryParams = std::multimap<std::string, std::string>;

enum class SkyRoute { kLookup, kEnvmap };

inline constexpr int kEnvmapMinWidth = 8;
inline constexpr int kEnvmapMaxWidth = 8192;
inline constexpr int kEnvmapDefaultWidth = 1024;
inline constexpr int kEnvmapMaxWidthAboveAtmosphere = 1024;
// width x width pixels: 4096 holds about as many as the widest lat-long map.
inline constexpr int kEnvmapMaxWidthEqualArea = 4096;

enum class EnvmapLayout { kLatlong, kEqualArea };

// A validated query, defaults filled in.
struct SkyQuery {
  Location location;
  std::optional<UtcInstant> time;
  std::optional<double> sun_zenith_deg, sun_azimuth_deg;  // as given
  AtmosphereSpec atmosphere;
  double min_nm = 360.0, max_nm = 830.0;
  double view_zenith_deg = 0.0, view_azimuth_deg = 0.0;  // lookup
  int width = kEnvmapDefaultWidth;                        // envmap
  EnvmapSun sun_mode = EnvmapSun::kDisk;                  // envmap
  EnvmapLayout layout = EnvmapLayout::kLatlong;           // envmap
  ColorSpace color_space = ColorSpace::kLinRec709;        // envmap
  RadiometricUnits units = RadiometricUnits::kCdM2;       // envmap
  // What the table is built from: the sun resolved (from time, or the angles).
  SkyTableParams table;

  // The canonical parameters (every default filled in, one spelling; the
  // layout only when it is not latlong, so older maps keep their bytes).
  nlohmann::json canonical_json(SkyRoute route) const;
};

// Parses and validates the query of a route.  Throws api::ValidationError
// listing every invalid parameter by its query name.
SkyQuery parse_sky_query(const QueryParams& params, SkyRoute route, int base_spectral_bins = 16);

// The route handlers.
class SkyHttp {
 public:
  // private_cache: answers are "private" (the API needs a token).
  SkyHttp(std::shared_ptr<SkyService> service, bool private_cache);

  void lookup(const httplib::Request& req, httplib::Response& res) const;
  void envmap(const httplib::Request& req, httplib::Response& res) const;

  SkyService& service() const { return *service_; }

 private:
  std::shared_ptr<SkyService> service_;
  const char* cache_control_;
};

}  // namespace skyfarm::server
