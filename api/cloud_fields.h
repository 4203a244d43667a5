// "clouds": procedural cloud layers and placed cloud volumes, read and written
// (the renderer's side: common/clouds/cloud_spec.h).
//
//   "clouds": {
//     "layers": [{                      at most kMaxCloudLayers
//       "type": "cumulus",              required: cumulus | stratocumulus | stratus |
//                                       cirrus | custom; fills every omitted field
//                                       below from cloud_layer_preset(type)
//                                       (custom: the cumulus values, a box profile)
//       "coverage": 0.4,                [0, 1], share of the sky the layer covers
//       "base_m": 1500,                 >= 0, bottom above the ground, metres
//       "thickness_m": 1500,            > 0, metres; base_m + thickness_m <= kMaxCloudTop_m
//       "water_content_g_m3": 0.5,      [0, 10] g m^-3 at full density, or
//       "optical_depth": 20,            [0, 1000] vertical optical depth (not both)
//       "effective_radius_um": 10,      water [0.5, 25], ice [5, 200] micrometres
//       "particle": "water",            water | ice
//       "seed": 7,                      integer in [0, 2^64 - 1], the shapes' seed
//       "wind_m_s": [east, north],      each finite, |wind| <= 100 m/s, or
//       "wind": {"speed_m_s": 8,        [0, 100] m/s
//                "from_deg": 270},      [0, 360], where the wind blows FROM,
//                                       clockwise from north (270: a west wind,
//                                       wind_m_s [+8, 0]); not both spellings
//       "scale_m": 3000,                >= 100, size of the coverage features
//       "detail_scale_m": 600,          >= 10, size of the eroding detail
//       "erosion": 0.4}],               [0, 1]
//     "volumes": [{                     at most kMaxCloudVolumes
//       "asset": "sha256:<64 hex>",     required: the id POST /v1/assets answered
//       "grid": "density",              the float grid's name, 1 to 64 characters
//       "placement": {"translate_m", "rotate_deg", "scale"},   as objects' (object_fields.h)
//       "density_scale": 0.05,          [0, 1] m^-1, extinction where the grid is 1
//       "effective_radius_um": 10,      as for layers
//       "particle": "water"}]}          as for layers
//
// A particle that differs from the type's (water in cirrus, ice elsewhere)
// without an effective_radius_um takes that particle's typical radius
// (kWaterRadius_um, kIceRadius_um) instead of the type's.  "optical_depth": 0
// means a layer that does not scatter (its water content becomes 0).
// With "method": "lut" layers are allowed, volumes are an error.  The
// canonical form writes "clouds" only when it holds a layer or a volume, so
// requests without clouds keep their text; every field is written, resolved
// (one of water_content_g_m3 and optical_depth: the one in force; the wind as
// wind_m_s).
#pragma once

#include <cstddef>

#include "api/json_fields.h"
#include "common/clouds/cloud_spec.h"

namespace skyfarm::api {

inline constexpr std::size_t kMaxCloudLayers = 8;
inline constexpr std::size_t kMaxCloudVolumes = 16;
// The highest cloud top: the tropopause reaches ~17-18 km in the tropics and
// the tallest cumulonimbus overshoot it by ~2 km; nothing the layer types
// stand for lies above 20 km (polar stratospheric clouds excepted).
inline constexpr double kMaxCloudTop_m = 20000.0;
inline constexpr double kMaxWind_m_s = 100.0;
inline constexpr double kMaxCloudOpticalDepth = 1000.0;
inline constexpr double kMaxWaterContent_g_m3 = 10.0;
inline constexpr double kMaxVolumeDensityScale_per_m = 1.0;
// The typical effective radii a particle that differs from its type's takes.
inline constexpr double kWaterRadius_um = 10.0;
inline constexpr double kIceRadius_um = 30.0;

// Reads "clouds" of the request object `top` into out (left unchanged when
// absent or invalid).
void read_clouds(const Fields& top, CloudsSpec& out);
// The canonical "clouds" object (callers write it only when !clouds.empty()).
Json clouds_json(const CloudsSpec& clouds);

// The wind velocity [east, north] of a wind blowing FROM `from_deg`
// (clockwise from north) at `speed_m_s`; exact at multiples of 90 degrees.
glm::dvec2 wind_from_direction(double speed_m_s, double from_deg);

}  // namespace skyfarm::api
