#include "worker/bench_efficiency.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/core/constants.h"
#include "common/material/material_library.h"
#include "common/material/surface_spec.h"
#include "common/render/radiance_control.h"
#include "common/render/scene.h"
#include "common/render/shadow_guide.h"
#include "common/render/render_plan.h"
#include "common/render/volume_path_integrator.h"

namespace skyfarm {
namespace {

struct EfficiencyResult {
  double relative_std_per_path = 0.0;
  double microseconds_per_path = 0.0;
  PathCounters counters;
  std::vector<std::array<double, 4>> rows;
};

// Unit vector of (zenith, azimuth) in the observer frame (z up, y north, x east).
glm::dvec3 direction(double zenith_deg, double azimuth_deg) {
  const double z = zenith_deg * kPi / 180.0, a = azimuth_deg * kPi / 180.0;
  return {std::sin(z) * std::sin(a), std::sin(z) * std::cos(a), std::cos(z)};
}

// "--ground NAME[:ROUGHNESS[:single]]": a named material on the ground
// (":single" for the single-bounce BSDF).
std::optional<material::SurfaceSpec> ground_from_arg(const std::string& arg) {
  material::SurfaceSpec s;
  const std::size_t colon = arg.find(':');
  s.name = arg.substr(0, colon);
  const auto id = material::find_material(s.name);
  if (!id) return std::nullopt;
  s.kind = material::named_material(*id).kind();
  if (colon != std::string::npos) s.roughness_x = s.roughness_y = std::atof(arg.c_str() + colon + 1);
  s.multiple_bounce = !arg.ends_with(":single");
  return s;
}

EfficiencyResult measure(double sun_zenith_deg, int samples, IntegratorOptions options, bool roulette_control,
                         bool shadow_guide, const std::optional<material::SurfaceSpec>& ground) {
  SunSpec sun;
  sun.zenith_deg = sun_zenith_deg;
  sun.azimuth_deg = 180.0;
  AtmosphereSpec atmosphere;
  atmosphere.ground_material = ground;
  const Scene scene = Scene::from_specs(atmosphere, sun, Location{}, std::nullopt, 360.0, 830.0);
  if (roulette_control) options.roulette_control = std::make_shared<const RadianceControl>(scene);
  if (shadow_guide && shadow_guide_pays(sun_zenith_deg)) options.shadow_guide = std::make_shared<const ShadowGuide>(scene);
  const VolumePathIntegrator integrator(scene, options);
  SampledWavelengths wl;
  wl.lambda_nm.fill(550.0);
  wl.pdf.fill(1.0);
  EfficiencyResult r;
  double sum_w_var = 0.0, sum_w_L2 = 0.0, sum_w_seconds = 0.0, sum_w = 0.0;
  std::vector<std::array<double, 4>> rows;  // per zenith row: zenith, w var, w L^2, mean L
  std::uint64_t pixel = 0;
  for (double zen = 2.5; zen < 180.0; zen += 5.0) {
    rows.push_back({zen, 0.0, 0.0, 0.0});
    for (double az = 7.5; az < 360.0; az += 15.0, ++pixel) {
      if (std::abs(zen - sun_zenith_deg) < 4.0 && std::abs(az - 180.0) < 10.0) continue;  // the disk
      const double w = std::sin(zen * kPi / 180.0);
      const Ray ray{scene.observer(), direction(zen, az)};
      double sum = 0.0, sum_sq = 0.0;
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < samples; ++i) {
        Sampler sampler(7, pixel, static_cast<std::uint64_t>(i));
        const double L = integrator.radiance(ray, wl, sampler, &r.counters)[0];
        sum += L;
        sum_sq += L * L;
      }
      sum_w_seconds += w * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double mean = sum / samples, var = std::max(0.0, sum_sq / samples - mean * mean);
      sum_w_var += w * var;
      sum_w_L2 += w * mean * mean;
      sum_w += w;
      rows.back()[1] += w * var;
      rows.back()[2] += w * mean * mean;
      rows.back()[3] += mean / 24.0;
    }
  }
  r.rows = rows;
  r.relative_std_per_path = sum_w_L2 > 0.0 ? std::sqrt(sum_w_var / sum_w_L2) : 0.0;
  r.microseconds_per_path = sum_w_seconds / sum_w / samples * 1e6;
  return r;
}

}  // namespace

int run_bench_efficiency(const std::vector<std::string>& args) {
  int samples = 1000;
  std::vector<double> suns;
  IntegratorOptions options;
  bool breakdown = false, roulette_control = false, shadow_guide = false;
  std::optional<material::SurfaceSpec> ground;
  std::string ground_arg;
  for (std::size_t i = 1; i < args.size(); ++i) {  // args[0] is "efficiency"
    if (args[i] == "--samples" && i + 1 < args.size()) {
      samples = std::max(2, std::atoi(args[++i].c_str()));
    } else if (args[i] == "--sun-zenith" && i + 1 < args.size()) {
      suns.push_back(std::atof(args[++i].c_str()));
    } else if (args[i] == "--shadow-scale" && i + 1 < args.size()) {
      options.shadow_majorant_scale = std::max(1.0, std::atof(args[++i].c_str()));
    } else if (args[i] == "--max-camera-scale" && i + 1 < args.size()) {
      options.max_camera_majorant_scale = std::atof(args[++i].c_str());
    } else if (args[i] == "--max-depth" && i + 1 < args.size()) {
      options.max_depth = std::atoi(args[++i].c_str());
    } else if (args[i] == "--forced-segments" && i + 1 < args.size()) {
      options.forced_collision_segments = std::atoi(args[++i].c_str());
    } else if (args[i] == "--camera-collisions" && i + 1 < args.size()) {
      options.camera_target_collisions = std::atof(args[++i].c_str());
    } else if (args[i] == "--rr-start-depth" && i + 1 < args.size()) {
      options.rr_start_depth = std::atoi(args[++i].c_str());
    } else if (args[i] == "--rr-threshold-in-shadow" && i + 1 < args.size()) {
      options.rr_threshold_in_shadow = std::atof(args[++i].c_str());
    } else if (args[i] == "--ground" && i + 1 < args.size()) {
      ground_arg = args[++i];
      ground = ground_from_arg(ground_arg);
      if (!ground) {
        std::cerr << "bench efficiency: --ground: unknown material \"" << ground_arg
                  << "\" (known: " << material::known_material_names() << ")\n";
        return 2;
      }
    } else if (args[i] == "--breakdown") {
      breakdown = true;
    } else if (args[i] == "--roulette-control") {
      roulette_control = true;
    } else if (args[i] == "--shadow-guide") {
      shadow_guide = true;
    } else if (args[i] == "--sunlit-segments") {
      options.explicit_single_scattering = true;
    } else if (args[i] == "--residual-below-cos" && i + 1 < args.size()) {
      options.residual_tracking_below_cos = std::atof(args[++i].c_str());
    } else if (args[i] == "--residual-below-altitude" && i + 1 < args.size()) {
      options.residual_tracking_below_altitude_m = std::atof(args[++i].c_str());
    } else if (args[i] == "--no-sunlit-in-shadow") {
      options.sunlit_segments_in_shadow = false;
    } else if (args[i] == "--plain-ratio-tracking") {
      options.residual_ratio_tracking = false;
    } else {
      std::cerr << "usage: skyfarm-worker bench efficiency [--samples N] [--sun-zenith DEG ...] "
                   "[--shadow-scale S] [--sunlit-segments] [--no-sunlit-in-shadow] [--plain-ratio-tracking] [--max-depth N]\n"
                   "  [--forced-segments K] [--camera-collisions N] [--max-camera-scale S] [--rr-start-depth D]\n"
                   "  [--rr-threshold-in-shadow W] [--residual-below-cos C] [--residual-below-altitude M] [--breakdown]\n"
                   "  [--roulette-control] [--shadow-guide] [--ground NAME[:ROUGHNESS[:single]]]\n";
      return 2;
    }
  }
  if (suns.empty()) suns = {30.0, 85.0, 96.0};
  for (const double sun : suns) {
    const EfficiencyResult r = measure(sun, samples, options, roulette_control, shadow_guide, ground);
    const double rel2 = r.relative_std_per_path * r.relative_std_per_path;
    std::cout << nlohmann::json{{"bench", "efficiency"},
                                {"sun_zenith_deg", sun},
                                {"ground", ground ? ground_arg : std::string("lambertian")},
                                {"samples_per_direction", samples},
                                {"shadow_majorant_scale", options.shadow_majorant_scale},
                                {"sunlit_segments", options.explicit_single_scattering},
                                {"residual_ratio_tracking", options.residual_ratio_tracking},
                                {"roulette_control", roulette_control},
                                {"shadow_guide", shadow_guide && shadow_guide_pays(sun)},
                                {"relative_std_per_path", r.relative_std_per_path},
                                {"microseconds_per_path", r.microseconds_per_path},
                                {"efficiency", rel2 > 0.0 ? 1.0 / (rel2 * r.microseconds_per_path) : 0.0},
                                {"nonfinite", r.counters.nonfinite},
                                {"collisions_per_path", static_cast<double>(r.counters.collisions) / static_cast<double>(std::max<std::uint64_t>(1, r.counters.paths))}}
                     .dump()
              << std::endl;
    if (breakdown) {
      double v = 0.0;
      for (const auto& row : r.rows) v += row[1];
      for (const auto& row : r.rows)
        std::cout << "  zenith " << row[0] << ": share of variance " << row[1] / v
                  << ", relative std per path " << (row[2] > 0.0 ? std::sqrt(row[1] / row[2]) : 0.0)
                  << ", mean " << row[3] << "\n";
    }
  }
  return 0;
}

}  // namespace skyfarm
