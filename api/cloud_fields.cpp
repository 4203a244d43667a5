#include "api/cloud_fields.h"

#include <cmath>
#include <numbers>
#include <string>

#include "api/object_fields.h"
#include "common/assets/asset_id.h"

namespace skyfarm::api {
namespace {

constexpr Choice<CloudType> kCloudTypes[] = {{"cumulus", CloudType::kCumulus},
                                             {"stratocumulus", CloudType::kStratocumulus},
                                             {"stratus", CloudType::kStratus},
                                             {"cirrus", CloudType::kCirrus},
                                             {"custom", CloudType::kCustom}};
constexpr Choice<CloudParticle> kParticles[] = {{"water", CloudParticle::kWater}, {"ice", CloudParticle::kIce}};
constexpr std::size_t kMaxGridNameChars = 64;

// Effective radii the optics take (common/clouds/cloud_optics.h): water, the
// range of its Mie summary table, 0.5-25 um; ice, which geometric optics
// would take at any size, from small quasi-spherical crystals to large
// aggregates, 5-200 um, so that a typing slip (2000) is an error.
Range radius_range(CloudParticle particle) {
  return particle == CloudParticle::kIce ? Range::closed(5, 200) : Range::closed(0.5, 25);
}
std::string_view radius_context(CloudParticle particle) {
  return particle == CloudParticle::kIce ? " for ice crystals" : " for water droplets";
}

// "particle" then "effective_radius_um": the radius default follows the
// particle when the particle is not the type's own.
void read_particle_and_radius(const Fields& f, CloudParticle preset_particle, CloudParticle& particle,
                              double& radius_um) {
  f.choice("particle", kParticles, particle);
  if (particle != preset_particle) radius_um = particle == CloudParticle::kIce ? kIceRadius_um : kWaterRadius_um;
  if (const Json* v = f.find("effective_radius_um"))
    if (auto r = read_number(*v, f.path_of("effective_radius_um"), radius_range(particle), f.errors(),
                             radius_context(particle)))
      radius_um = *r;
}

// (sin, cos) of an angle in degrees, exact at multiples of 90 so that a
// west wind has no 1e-16 northward part.
glm::dvec2 sin_cos_deg(double deg) {
  double a = std::fmod(deg, 360.0);
  if (a < 0) a += 360.0;
  if (a == 0.0) return {0.0, 1.0};
  if (a == 90.0) return {1.0, 0.0};
  if (a == 180.0) return {0.0, -1.0};
  if (a == 270.0) return {-1.0, 0.0};
  const double r = a * (std::numbers::pi / 180.0);
  return {std::sin(r), std::cos(r)};
}

// "wind_m_s" | "wind": one spelling, a velocity of at most kMaxWind_m_s.
void read_wind(const Fields& f, glm::dvec2& out) {
  Errors& e = f.errors();
  const Json* vector = f.find("wind_m_s");
  const Json* polar = f.find("wind");
  if (vector && polar) {
    e.add(f.path_of("wind"), "give either wind_m_s or wind, not both", value_text(*polar));
    return;
  }
  if (vector) {
    const std::string path = f.path_of("wind_m_s");
    const auto v = read_number_array(*vector, path, {2, 2, Range::closed(-kMaxWind_m_s, kMaxWind_m_s), false}, e);
    if (!v) return;
    const glm::dvec2 w{(*v)[0], (*v)[1]};
    if (std::hypot(w.x, w.y) > kMaxWind_m_s) {
      e.add(path, "must be [east, north] with a speed of at most 100 m/s", value_text(*vector));
      return;
    }
    out = w;
    return;
  }
  if (!polar) return;
  const std::string path = f.path_of("wind");
  if (!expect_object(*polar, path, e)) return;
  Fields w(*polar, path, e);
  w.allow_only({"speed_m_s", "from_deg"});
  double speed = 0.0, from = 0.0;
  bool ok = true;
  for (const char* name : {"speed_m_s", "from_deg"})
    if (!w.find(name)) {
      e.add(w.path_of(name), "required");
      ok = false;
    }
  ok = w.number("speed_m_s", Range::closed(0, kMaxWind_m_s), speed) && ok;
  ok = w.number("from_deg", Range::closed(0, 360), from) && ok;
  if (ok) out = wind_from_direction(speed, from);
}

void read_layer(const Fields& f, CloudLayerSpec& out) {
  f.allow_only({"type", "coverage", "base_m", "thickness_m", "water_content_g_m3", "optical_depth",
                "effective_radius_um", "particle", "seed", "wind_m_s", "wind", "scale_m", "detail_scale_m",
                "erosion"});
  Errors& e = f.errors();
  CloudType type = CloudType::kCumulus;
  if (!f.find("type")) {
    e.add(f.path_of("type"), "required (" + one_of_rule({"cumulus", "stratocumulus", "stratus", "cirrus", "custom"}) + ")");
  } else {
    f.choice("type", kCloudTypes, type);
  }
  CloudLayerSpec s = cloud_layer_preset(type);
  f.number("coverage", Range::closed(0, 1), s.coverage);
  const bool base_ok = f.number("base_m", Range::closed(0, kMaxCloudTop_m), s.base_m) || !f.find("base_m");
  const bool thickness_ok =
      f.number("thickness_m", Range::open_closed(0, kMaxCloudTop_m), s.thickness_m) || !f.find("thickness_m");
  if (base_ok && thickness_ok && s.base_m + s.thickness_m > kMaxCloudTop_m) {
    const bool thickness_given = f.find("thickness_m");
    e.add(f.path_of(thickness_given ? "thickness_m" : "base_m"),
          "base_m + thickness_m must be at most 20000 (the cloud top, metres above the ground)",
          format_number(s.base_m) + " + " + format_number(s.thickness_m));
  }
  const Json* water = f.find("water_content_g_m3");
  const Json* tau = f.find("optical_depth");
  if (water && tau) {
    e.add(f.path_of("optical_depth"), "give either water_content_g_m3 or optical_depth, not both", value_text(*tau));
  } else if (tau) {
    if (f.number("optical_depth", Range::closed(0, kMaxCloudOpticalDepth), s.optical_depth) && s.optical_depth == 0.0)
      s.water_content_g_m3 = 0.0;
  } else {
    f.number("water_content_g_m3", Range::closed(0, kMaxWaterContent_g_m3), s.water_content_g_m3);
    s.optical_depth = 0.0;
  }
  read_particle_and_radius(f, s.particle, s.particle, s.effective_radius_um);
  if (const Json* seed = f.find("seed"))
    if (auto v = read_uint64(*seed, f.path_of("seed"), e)) s.seed = *v;
  read_wind(f, s.wind_m_s);
  f.number("scale_m", Range::at_least(100), s.scale_m);
  f.number("detail_scale_m", Range::at_least(10), s.detail_scale_m);
  f.number("erosion", Range::closed(0, 1), s.erosion);
  out = s;
}

void read_volume(const Fields& f, CloudVolumeSpec& out) {
  f.allow_only({"asset", "grid", "placement", "density_scale", "effective_radius_um", "particle"});
  Errors& e = f.errors();
  CloudVolumeSpec s;
  const Json* asset = f.find("asset");
  if (!asset) {
    e.add(f.path_of("asset"), "required: the id POST /v1/assets answered (\"sha256:...\")");
  } else if (!asset->is_string() || !assets::is_asset_id(asset->get_ref<const std::string&>())) {
    e.add(f.path_of("asset"), "must be an asset id, \"sha256:\" and 64 lowercase hex digits (POST /v1/assets)",
          value_text(*asset));
  } else {
    s.asset = asset->get<std::string>();
  }
  if (const Json* grid = f.find("grid")) {
    if (grid->is_string() && !grid->get_ref<const std::string&>().empty() &&
        grid->get_ref<const std::string&>().size() <= kMaxGridNameChars)
      s.grid = grid->get<std::string>();
    else
      e.add(f.path_of("grid"), "must be a string of 1 to " + std::to_string(kMaxGridNameChars) + " characters",
            value_text(*grid));
  }
  if (const Json* placement = f.find("placement")) {
    const std::string path = f.path_of("placement");
    if (expect_object(*placement, path, e)) {
      Fields p(*placement, path, e);
      p.allow_only({"translate_m", "rotate_deg", "scale"});
      read_placement(p, s.placement);
    }
  }
  f.number("density_scale", Range::closed(0, kMaxVolumeDensityScale_per_m), s.density_scale);
  read_particle_and_radius(f, CloudParticle::kWater, s.particle, s.effective_radius_um);
  out = s;
}

// An array of at most max_count objects, each read by `read`; `out` is
// replaced only when every entry is valid.
template <class T, class Read>
void read_list(const Fields& f, std::string_view name, std::size_t max_count, std::vector<T>& out, Read read) {
  const Json* v = f.find(name);
  if (!v) return;
  const std::string path = f.path_of(name);
  Errors& e = f.errors();
  if (!expect_array(*v, path, 0, max_count, e)) return;
  std::vector<T> items(v->size());
  const std::size_t before = e.size();
  for (std::size_t i = 0; i < v->size(); ++i) {
    const std::string item = index_path(path, i);
    if (expect_object((*v)[i], item, e)) read(Fields((*v)[i], item, e), items[i]);
  }
  if (e.size() == before) out = std::move(items);
}

Json layer_json(const CloudLayerSpec& s) {
  Json j = {{"type", std::string(name_of(kCloudTypes, s.type))},
            {"coverage", canonical_number(s.coverage)},
            {"base_m", canonical_number(s.base_m)},
            {"thickness_m", canonical_number(s.thickness_m)},
            {"effective_radius_um", canonical_number(s.effective_radius_um)},
            {"particle", std::string(name_of(kParticles, s.particle))},
            {"seed", s.seed},
            {"wind_m_s", Json::array({canonical_number(s.wind_m_s.x), canonical_number(s.wind_m_s.y)})},
            {"scale_m", canonical_number(s.scale_m)},
            {"detail_scale_m", canonical_number(s.detail_scale_m)},
            {"erosion", canonical_number(s.erosion)}};
  // The one in force: optical_depth > 0 overrides the water content.
  if (s.optical_depth > 0.0)
    j["optical_depth"] = canonical_number(s.optical_depth);
  else
    j["water_content_g_m3"] = canonical_number(s.water_content_g_m3);
  return j;
}

Json volume_json(const CloudVolumeSpec& s) {
  Json placement = Json::object();
  placement_json(s.placement, placement);
  return {{"asset", s.asset},
          {"grid", s.grid},
          {"placement", placement},
          {"density_scale", canonical_number(s.density_scale)},
          {"effective_radius_um", canonical_number(s.effective_radius_um)},
          {"particle", std::string(name_of(kParticles, s.particle))}};
}

}  // namespace

// A wind from azimuth phi blows towards phi + 180: its velocity is
// -speed (sin phi, cos phi) in (east, north), azimuth clockwise from north
// (the meteorological convention, WMO-No. 8, part I, ch. 5).
glm::dvec2 wind_from_direction(double speed_m_s, double from_deg) {
  const glm::dvec2 sc = sin_cos_deg(from_deg);
  return {canonical_number(-speed_m_s * sc.x), canonical_number(-speed_m_s * sc.y)};
}

void read_clouds(const Fields& top, CloudsSpec& out) {
  const Json* v = top.find("clouds");
  if (!v) return;
  const std::string path = top.path_of("clouds");
  Errors& e = top.errors();
  if (!expect_object(*v, path, e)) return;
  Fields f(*v, path, e);
  f.allow_only({"layers", "volumes"});
  CloudsSpec clouds;
  const std::size_t before = e.size();
  read_list(f, "layers", kMaxCloudLayers, clouds.layers, read_layer);
  read_list(f, "volumes", kMaxCloudVolumes, clouds.volumes, read_volume);
  if (e.size() == before) out = std::move(clouds);
}

Json clouds_json(const CloudsSpec& clouds) {
  Json layers = Json::array(), volumes = Json::array();
  for (const CloudLayerSpec& s : clouds.layers) layers.push_back(layer_json(s));
  for (const CloudVolumeSpec& s : clouds.volumes) volumes.push_back(volume_json(s));
  return {{"layers", layers}, {"volumes", volumes}};
}

}  // namespace skyfarm::api
