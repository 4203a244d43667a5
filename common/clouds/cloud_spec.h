// What a request asks of the clouds: procedural cloud layers and placed cloud
// volumes (OpenVDB grids uploaded as assets).  Plain values, resolved: every
// field holds a number (the request's layer type fills what it omits, see
// cloud_layer_preset).
//
// Layer parameters (CloudLayerSpec)
//   type                 cumulus | stratocumulus | stratus | cirrus | custom:
//                        the height profile and the defaults of the fields below
//   coverage             0..1: the share of the layer's area that holds cloud
//                        (0: none at all, 1: overcast)
//   base_m, thickness_m  the layer's bottom altitude above the ground and its
//                        depth, metres
//   water_content_g_m3   liquid (or ice) water content where the density is
//                        full, g m^-3; the extinction follows from it and the
//                        droplet size (cloud_optics.h).  Ignored when
//   optical_depth        > 0: the vertical optical depth through the layer
//                        where the coverage is full and nothing erodes it
//   effective_radius_um  droplet (or ice crystal) effective radius, micrometres
//   particle             water droplets (Mie) or ice crystals (cirrus)
//   seed                 the procedural shapes' seed (the same bits on every worker)
//   wind_m_s             [east, north] the velocity the air moves with (a west
//                        wind is [+u, 0]): the shapes drift by wind x (time - J2000)
//   scale_m              horizontal size of the coverage features, metres
//   detail_scale_m       size of the eroding detail noise, metres
//   erosion              0..1: how much the detail noise eats the edges
//
// Volume parameters (CloudVolumeSpec)
//   asset                "sha256:<hex>" of an uploaded OpenVDB file (or, for
//                        skyfarm-worker render, a file path)
//   grid                 the float grid's name in the file ("density")
//   placement            in the observer's east-north-up frame (as objects)
//   density_scale        extinction coefficient, m^-1, where the grid's value is 1
//   effective_radius_um, particle   as for layers (the phase function and albedo)
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>

#include "common/geometry/placement.h"

namespace skyfarm {

enum class CloudType { kCumulus, kStratocumulus, kStratus, kCirrus, kCustom };
enum class CloudParticle { kWater, kIce };

struct CloudLayerSpec {
  CloudType type = CloudType::kCumulus;
  double coverage = 0.4;
  double base_m = 1500.0;
  double thickness_m = 1500.0;
  double water_content_g_m3 = 0.5;
  double optical_depth = 0.0;  // > 0 overrides water_content_g_m3
  double effective_radius_um = 10.0;
  CloudParticle particle = CloudParticle::kWater;
  std::uint64_t seed = 1;
  glm::dvec2 wind_m_s{0.0, 0.0};
  double scale_m = 3000.0;
  double detail_scale_m = 600.0;
  double erosion = 0.4;
};

struct CloudVolumeSpec {
  std::string asset;
  std::string grid = "density";
  Placement placement;
  double density_scale = 0.05;
  double effective_radius_um = 10.0;
  CloudParticle particle = CloudParticle::kWater;
};

struct CloudsSpec {
  std::vector<CloudLayerSpec> layers;
  std::vector<CloudVolumeSpec> volumes;
  bool empty() const { return layers.empty() && volumes.empty(); }
};

// The defaults of a layer type (custom: those of cumulus, its profile a
// plain box with soft edges).
CloudLayerSpec cloud_layer_preset(CloudType type);

// "cumulus", ... and back; false / nullopt-like: the parse returns false on an unknown name.
std::string_view cloud_type_name(CloudType type);
bool parse_cloud_type(std::string_view name, CloudType* type);
std::string_view cloud_particle_name(CloudParticle particle);
bool parse_cloud_particle(std::string_view name, CloudParticle* particle);

}  // namespace skyfarm
