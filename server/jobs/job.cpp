#include "server/jobs/job.h"

#include <algorithm>
#include <cmath>

#include "common/atmosphere/atmosphere_builder.h"
#include "common/material/surface.h"
#include "common/render/render_progress.h"

namespace skyfarm::server {

WorkUnit unit_at(const RenderPlan& plan, std::size_t i) {
  const std::size_t per_pass = static_cast<std::size_t>(plan.tile_count()) * static_cast<std::size_t>(plan.batches);
  const std::size_t rem = i % per_pass;
  return WorkUnit{static_cast<int>(rem / static_cast<std::size_t>(plan.batches)),
                  static_cast<int>(rem % static_cast<std::size_t>(plan.batches)), static_cast<int>(i / per_pass)};
}

std::int64_t waiting_units(const RenderPlan& plan, std::int64_t merged) {
  const std::int64_t per_pass = static_cast<std::int64_t>(plan.tile_count()) * plan.batches;
  return std::max<std::int64_t>(0, std::min(plan.unit_count() - merged, per_pass * kQueueHorizonPasses));
}

std::string unit_text(const WorkUnit& u) {
  return "tile " + std::to_string(u.tile) + ", batch " + std::to_string(u.batch) + ", pass " + std::to_string(u.pass);
}

namespace {

// The ground as the renderer sees it: its material and BSDF model, and the
// albedo the tables use (the white-sky albedo of a material) at 550 nm.
nlohmann::json ground_report(const AtmosphereSpec& spec, const Atmosphere& atmosphere) {
  nlohmann::json g = {{"albedo_550", atmosphere.ground().albedo(550.0)}};
  if (!spec.ground_material) {
    g["material"] = "lambertian";
    g["model"] = "lambertian";
    return g;
  }
  const material::Surface surface(*spec.ground_material);
  g["material"] = surface.material().name();
  g["model"] = surface.model_name();
  g["roughness"] = {spec.ground_material->roughness_x, spec.ground_material->roughness_y};
  return g;
}

// What the scene holds besides the sky: objects by shape, and whether the
// scene builds a BVH (only mesh objects need one).
nlohmann::json objects_report(const std::vector<ObjectSpec>& objects) {
  static constexpr const char* kNames[] = {"sphere", "disc", "rectangle", "box", "mesh"};
  nlohmann::json shapes = nlohmann::json::object();
  bool bvh = false;
  for (const ObjectSpec& o : objects) {
    const std::string name = kNames[static_cast<int>(o.shape)];
    shapes[name] = shapes.value(name, 0) + 1;
    bvh = bvh || o.shape == ShapeKind::kMesh;
  }
  return {{"count", objects.size()}, {"shapes", shapes}, {"bvh", bvh}};
}

// The clouds a request names: its layers by type (in order) and its volumes.
nlohmann::json clouds_report(const CloudsSpec& clouds) {
  nlohmann::json types = nlohmann::json::array();
  for (const CloudLayerSpec& layer : clouds.layers) types.push_back(std::string(cloud_type_name(layer.type)));
  return {{"layers", clouds.layers.size()}, {"layer_types", types}, {"volumes", clouds.volumes.size()}};
}

}  // namespace

nlohmann::json plan_report(const api::RenderRequest& request, const RenderPlan& plan) {
  nlohmann::json constituents = nlohmann::json::array(), skipped = nlohmann::json::array();
  const Atmosphere atmosphere = build_atmosphere(request.atmosphere);
  for (const auto& c : atmosphere.constituents()) constituents.push_back(c.name);
  if (request.atmosphere.preset != AtmospherePreset::kCustom) {
    if (request.atmosphere.ozone_du <= 0.0) skipped.push_back("ozone");
    if (!request.atmosphere.aerosol || request.atmosphere.aerosol->optical_depth_550 <= 0.0)
      skipped.push_back("aerosol");
  }
  nlohmann::json report = {{"constituents", constituents}, {"skipped", skipped},       {"ground", ground_report(request.atmosphere, atmosphere)},
          {"tiles", plan.tile_count()},
          {"batches", plan.batches},      {"passes", plan.passes},    {"samples_per_pass", plan.samples_per_pass},
          {"tile_size", plan.tile_size},  {"units", plan.unit_count()},  {"mirrored", plan.mirrored},
          {"method", plan.lut ? "lut" : "path"}, {"roulette_control", plan.roulette_control},
          {"shadow_guide", plan.shadow_guide},     {"adaptive", plan.adaptive},
          {"pooled_ground_row", plan.pooled_ground_row >= 0 ? nlohmann::json(plan.pooled_ground_row) : nlohmann::json()}};
  if (!request.objects.empty()) report["objects"] = objects_report(request.objects);
  // Nothing for a clear sky: its report stays as it was.
  if (!request.clouds.empty()) report["clouds"] = clouds_report(request.clouds);
  return report;
}

}  // namespace skyfarm::server
