#include "common/clouds/cloud_spec.h"

#include <array>

namespace skyfarm {

// Typical values of each genus (Rogers & Yau 1989, ch. 10; Stephens 1978 for
// the water contents and droplet radii; Heymsfield & McFarquhar 2002 for
// cirrus): the defaults a request's layer type fills in.
CloudLayerSpec cloud_layer_preset(CloudType type) {
  CloudLayerSpec s;
  s.type = type;
  switch (type) {
    case CloudType::kCumulus:
    case CloudType::kCustom:
      break;  // the struct's defaults: fair-weather cumulus
    case CloudType::kStratocumulus:
      s.coverage = 0.7;
      s.base_m = 1000.0;
      s.thickness_m = 500.0;
      s.water_content_g_m3 = 0.3;
      s.effective_radius_um = 8.0;
      s.scale_m = 5000.0;
      s.detail_scale_m = 800.0;
      s.erosion = 0.3;
      break;
    case CloudType::kStratus:
      s.coverage = 1.0;
      s.base_m = 400.0;
      s.thickness_m = 400.0;
      s.water_content_g_m3 = 0.25;
      s.effective_radius_um = 8.0;
      s.scale_m = 10000.0;
      s.detail_scale_m = 1500.0;
      s.erosion = 0.1;
      break;
    case CloudType::kCirrus:
      s.coverage = 0.5;
      s.base_m = 9000.0;
      s.thickness_m = 1500.0;
      s.water_content_g_m3 = 0.02;
      s.effective_radius_um = 30.0;
      s.particle = CloudParticle::kIce;
      s.scale_m = 8000.0;
      s.detail_scale_m = 1500.0;
      s.erosion = 0.5;
      break;
  }
  return s;
}

namespace {
constexpr std::array<std::string_view, 5> kTypeNames = {"cumulus", "stratocumulus", "stratus", "cirrus", "custom"};
}

std::string_view cloud_type_name(CloudType type) { return kTypeNames[static_cast<std::size_t>(type)]; }

bool parse_cloud_type(std::string_view name, CloudType* type) {
  for (std::size_t i = 0; i < kTypeNames.size(); ++i) {
    if (kTypeNames[i] == name) {
      *type = static_cast<CloudType>(i);
      return true;
    }
  }
  return false;
}

std::string_view cloud_particle_name(CloudParticle particle) {
  return particle == CloudParticle::kIce ? "ice" : "water";
}

bool parse_cloud_particle(std::string_view name, CloudParticle* particle) {
  if (name == "water") *particle = CloudParticle::kWater;
  else if (name == "ice") *particle = CloudParticle::kIce;
  else return false;
  return true;
}

}  // namespace skyfarm
