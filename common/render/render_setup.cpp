#include "common/render/render_setup.h"

#include <optional>
#include <stdexcept>
#include <string>

#include "common/assets/volume_source.h"
#include "common/clouds/cloud_layer.h"
#include "common/clouds/cloud_optics.h"
#include "common/clouds/cloud_volume.h"
#include "common/objects/placed_objects.h"

namespace skyfarm {

namespace {

// Seconds since J2000 (2000-01-01T12:00:00Z) that the wind has blown: the
// clouds of a timelapse drift frame by frame; a render without a time has none.
double wind_time_s(const std::optional<UtcInstant>& time) {
  if (!time) return 0.0;
  constexpr std::int64_t kJ2000_unix = 946728000;
  return static_cast<double>(time->unix_seconds - kJ2000_unix) + time->fraction;
}

}  // namespace

std::shared_ptr<const SceneClouds> make_scene_clouds(const RenderSpec& spec, double planet_radius_m,
                                                     const assets::VolumeSource* volumes) {
  if (spec.clouds.empty()) return nullptr;
  std::vector<std::shared_ptr<const CloudField>> fields;
  const double time_s = wind_time_s(spec.time);
  // The air has moved by time x wind since J2000.  The world frame's +x and
  // +y are the observer's east and north (ray.h), so the displacement there is
  // (east, north, 0) x time; CloudLayer translates its noise rigidly by it.
  for (const CloudLayerSpec& layer : spec.clouds.layers) {
    const glm::dvec3 drift_m = time_s * glm::dvec3(layer.wind_m_s.x, layer.wind_m_s.y, 0.0);
    fields.push_back(std::make_shared<CloudLayer>(layer, planet_radius_m, drift_m));
  }
  // Volumes: the grid from the source (its errors name the asset, and a
  // worker's "try again later" must reach the worker as it is), placed as objects are.
  if (!spec.clouds.volumes.empty() && !volumes) throw std::runtime_error("cloud volumes need a volume source");
  for (std::size_t i = 0; i < spec.clouds.volumes.size(); ++i) {
    const CloudVolumeSpec& v = spec.clouds.volumes[i];
    std::shared_ptr<const assets::VolumeGrid> grid = volumes->volume(v.asset);
    try {
      fields.push_back(std::make_shared<CloudVolume>(std::move(grid), v.placement, v.density_scale,
                                                     cloud_optics(v.particle, v.effective_radius_um),
                                                     planet_radius_m));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("clouds.volumes[" + std::to_string(i) + "]: " + e.what());
    }
  }
  return std::make_shared<SceneClouds>(std::move(fields));
}

RenderSetup make_render_setup(const RenderSpec& spec, const assets::MeshSource* meshes,
                              const assets::VolumeSource* volumes) {
  RenderSetup s;
  s.scene = std::make_unique<Scene>(Scene::from_specs(spec.atmosphere, spec.sun, spec.location, spec.time,
                                                      spec.lambda_min_nm, spec.lambda_max_nm));
  // Objects only when there are some: a plain sky builds nothing for them.
  if (!spec.objects.empty())
    s.scene->set_objects(
        std::make_shared<PlacedObjects>(spec.objects, s.scene->atmosphere().planet_radius_m(), meshes));
  // Clouds likewise: a clear sky builds nothing and takes the same code.
  if (!spec.clouds.empty())
    s.scene->set_clouds(make_scene_clouds(spec, s.scene->atmosphere().planet_radius_m(), volumes));
  s.camera = std::make_unique<Camera>(spec.camera, s.scene->observer());
  s.plan = render_plan_for(spec, s.scene->sun());
  return s;
}

RenderPlan render_plan_for(const RenderSpec& spec, const Sun& sun) {
  constexpr int kTileSize = 32, kSamplesPerPass = 16;
  const bool lut = spec.lut;
  // A ground that is not Lambertian looks different from every direction
  // (no pooling), and an anisotropic one is not symmetric about the sun;
  // objects break both (they stand on the ground, anywhere about the sun),
  // and so do clouds (their shadows fall anywhere).
  const std::optional<material::SurfaceSpec>& ground = spec.atmosphere.ground_material;
  const bool uneven = !spec.objects.empty() || !spec.clouds.empty();
  const bool glossy_ground = ground && !(ground->kind == material::MaterialKind::kDiffuse && ground->smooth());
  // The LUT renderer is deterministic: one sample per pixel and batch, one pass.
  RenderPlan plan = make_render_plan(spec.camera.width, spec.camera.height, spec.lambda_min_nm, spec.lambda_max_nm,
                                     spec.batches, lut ? 1 : spec.samples_per_pixel, spec.seed, kTileSize,
                                     lut ? 1 : kSamplesPerPass,
                                     !uneven && (!ground || ground->isotropic()) &&
                                         mirror_symmetric(spec.camera, sun.azimuth_deg(), kTileSize));
  plan.lut = lut;
  plan.roulette_control = !lut && roulette_control_pays(sun.zenith_deg());
  plan.shadow_guide = !lut && shadow_guide_pays(sun.zenith_deg());
  plan.adaptive = !lut && spec.adaptive && plan.passes >= 2;
  // An observer on the ground sees one ground point in every downward
  // direction (common/film/ground_pool.h).
  if (!lut && spec.location.altitude_m == 0.0 && !glossy_ground && !uneven) plan.pooled_ground_row = first_ground_row(spec.camera);
  return plan;
}

void set_render_metadata(Image* image, std::string_view canonical_request, const RenderPlan& plan, const Sun& sun,
                         double samples_per_pixel, const ErrorSums& error) {
  namespace key = metadata_key;
  image->set_metadata(key::kRequest, std::string(canonical_request));
  image->set_metadata(key::kSunZenithDeg, sun.zenith_deg());
  image->set_metadata(key::kSunAzimuthDeg, sun.azimuth_deg());
  image->set_metadata(key::kSamplesPerPixel, static_cast<double>(samples_per_pixel));
  image->set_metadata(key::kWavelengthMinNm, plan.lambda_min_nm);
  image->set_metadata(key::kWavelengthMaxNm, plan.lambda_max_nm);
  image->set_metadata(key::kSoftwareVersion, software_version_text());
  if (const auto e = error.relative_rms()) image->set_metadata(key::kEstimatedRelativeRms, *e);
  if (const auto e = error.relative_rms_rgb()) {
    image->set_metadata(key::kEstimatedRelativeRmsR, e->r);
    image->set_metadata(key::kEstimatedRelativeRmsG, e->g);
    image->set_metadata(key::kEstimatedRelativeRmsB, e->b);
  }
  image->set_metadata(key::kMethod, std::string(plan.lut ? "lut" : "path"));
  if (plan.lut)
    image->set_metadata(key::kApproximate,
                        std::string("table-based sky (Hillaire 2020); error against the path tracer: README"));
  image->set_metadata(key::kEarthSunDistanceAu, sun.distance_au());
}

}  // namespace skyfarm
