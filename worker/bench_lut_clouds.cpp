#include "worker/bench_lut_clouds.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "common/clouds/cloud_optics.h"
#include "common/clouds/uniform_cloud_slab.h"
#include "common/film/image.h"
#include "common/geometry/sphere_intersection.h"
#include "common/lut/cloud_march.h"
#include "common/render/local_render.h"
#include "common/render/render_setup.h"
#include "common/render/tile_renderer.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 72, kHeight = 36;
constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kSunZeniths[] = {40.0, 70.0};
constexpr double kAltitudes[] = {0.0, 4000.0};
constexpr const char* kScenes[] = {"slab", "cumulus"};

RenderSpec case_spec(const std::string& scene, double sun_zenith, double altitude, bool lut, int spp) {
  RenderSpec spec;
  spec.location.altitude_m = altitude;
  spec.sun.zenith_deg = sun_zenith;
  spec.sun.azimuth_deg = 180.0;
  spec.camera.projection = Projection::kEquirectangular;
  spec.camera.width = kWidth;
  spec.camera.height = kHeight;
  spec.camera.yaw_deg = 180.0;
  spec.samples_per_pixel = lut ? 1 : spp;
  spec.lut = lut;
  spec.seed = 91;
  if (scene == "cumulus") spec.clouds.layers.push_back(cloud_layer_preset(CloudType::kCumulus));
  return spec;
}

RenderSetup case_setup(const std::string& scene, double sun_zenith, double altitude, bool lut, int spp) {
  const RenderSpec spec = case_spec(scene, sun_zenith, altitude, lut, spp);
  RenderSetup setup = make_render_setup(spec);
  if (scene == "slab") {
    // The plan of a cloudy request (no mirroring, no pooled ground).
    RenderSpec cloudy = spec;
    cloudy.clouds.layers.emplace_back();
    setup.plan = render_plan_for(cloudy, setup.scene->sun());
    // Vertical tau 8 over 1-2 km: an overcast stratus.
    setup.scene->set_clouds(std::make_shared<SceneClouds>(std::vector<std::shared_ptr<const CloudField>>{
        std::make_shared<UniformCloudSlab>(setup.scene->atmosphere().planet_radius_m(), 1000.0, 2000.0, 8.0 / 1000.0,
                                           cloud_optics(CloudParticle::kWater, 10.0))}));
  }
  return setup;
}

struct CloudFrame {
  std::vector<float> Y;               // luminance per pixel
  std::vector<float> variance;        // the path tracer's variance of Y's mean (0 for the LUT)
  std::vector<float> T_cloud;         // the LUT march's cloud transmittance at the pixel centre
  double seconds = 0.0;
};

CloudFrame render_frame(const std::string& scene, double sun_zenith, double altitude, bool lut, int spp,
                        const CloudMarchOptions& options = {}) {
  const RenderSetup setup = case_setup(scene, sun_zenith, altitude, lut, spp);
  const auto t0 = std::chrono::steady_clock::now();
  const Scene& sc = *setup.scene;
  const TileRenderer renderer =
      lut ? TileRenderer(sc, *setup.camera, setup.plan,
                         std::make_shared<const LutSky>(LutSky::build(sc.atmosphere(), sc.sun(), sc.observer_altitude_m(),
                                                                      setup.plan.lambda_min_nm,
                                                                      setup.plan.lambda_max_nm)),
                         options)
          : TileRenderer(sc, *setup.camera, setup.plan);
  Image image(kWidth, kHeight, ImageLayers{std::nullopt, true});
  render_image(renderer, &image, 0);
  CloudFrame f;
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double Y = image.luminance(x, y);
      f.Y.push_back(static_cast<float>(Y));
      const double rel = lut ? 0.0 : image.relative_error(x, y).value_or(0.0f);
      f.variance.push_back(static_cast<float>(rel * Y * rel * Y));
      double T = 1.0;
      if (const CloudMarch* march = renderer.lut_clouds()) {
        Ray ray;
        if (setup.camera->generate_ray(x, y, 0.5, 0.5, &ray)) {
          std::vector<double> L(static_cast<std::size_t>(64 * 8)), Tc(L.size());
          const double R = setup.scene->atmosphere().planet_radius_m();
          const Ray from{setup.scene->observer(), ray.d};
          const double t_ground = ground_distance(from, R);
          T = march->march(from, t_ground >= 0.0 ? t_ground : 1e12, L, Tc).transmittance;
        }
      }
      f.T_cloud.push_back(static_cast<float>(T));
    }
  return f;
}

CloudFrame reference(const std::string& scene, double sun_zenith, double altitude, int spp, const fs::path& dir) {
  const fs::path cache = dir / ("path_" + scene + "_sun" + std::to_string(static_cast<int>(sun_zenith)) + "_alt" +
                                std::to_string(static_cast<int>(altitude)) + "_spp" + std::to_string(spp) + ".bin");
  const std::size_t n = static_cast<std::size_t>(kWidth * kHeight);
  CloudFrame f;
  f.Y.resize(n);
  f.variance.resize(n);
  if (std::ifstream in(cache, std::ios::binary);
      in && in.read(reinterpret_cast<char*>(f.Y.data()), static_cast<std::streamsize>(n * 4)) &&
      in.read(reinterpret_cast<char*>(f.variance.data()), static_cast<std::streamsize>(n * 4)) &&
      in.read(reinterpret_cast<char*>(&f.seconds), sizeof(double)))
    return f;
  f = render_frame(scene, sun_zenith, altitude, false, spp);
  std::ofstream out(cache, std::ios::binary);
  out.write(reinterpret_cast<const char*>(f.Y.data()), static_cast<std::streamsize>(n * 4));
  out.write(reinterpret_cast<const char*>(f.variance.data()), static_cast<std::streamsize>(n * 4));
  out.write(reinterpret_cast<const char*>(&f.seconds), sizeof(double));
  return f;
}

struct Region {
  double w_lut = 0.0, w_path = 0.0, w_var = 0.0, w = 0.0;
  int pixels = 0;
  std::vector<double> ratios;  // Y_lut / Y_path per pixel
  // The median of Y_lut / Y_path - 1: robust to the reference's outliers.
  double median_error() {
    if (ratios.empty()) return 0.0;
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2), ratios.end());
    return ratios[ratios.size() / 2] - 1.0;
  }
  double rel_error() const { return w_path > 0.0 ? w_lut / w_path - 1.0 : 0.0; }
  // The reference's own relative standard error of the region's mean.
  double ref_error() const { return w_path > 0.0 ? std::sqrt(w_var) / w_path : 0.0; }
};

}  // namespace

int run_bench_lut_clouds(const std::vector<std::string>& args) {
  fs::path dir = "skyfarm-lut-clouds";
  int spp = 256;
  CloudMarchOptions options;
  for (std::size_t i = 1; i < args.size(); ++i) {  // args[0] is "lut-clouds"
    if (args[i] == "--out" && i + 1 < args.size()) {
      dir = args[++i];
    } else if (args[i] == "--spp" && i + 1 < args.size()) {
      spp = std::max(16, std::atoi(args[++i].c_str()));
    } else if (args[i] == "--octaves" && i + 1 < args.size()) {
      options.octaves = std::atoi(args[++i].c_str());
    } else if (args[i] == "--octave-abc" && i + 3 < args.size()) {
      options.octave_a = std::atof(args[++i].c_str());
      options.octave_b = std::atof(args[++i].c_str());
      options.octave_c = std::atof(args[++i].c_str());
    } else if (args[i] == "--octaves-only") {
      options.multiple_scattering = CloudMultipleScattering::kOctaves;
    } else if (args[i] == "--no-ambient") {
      options.ambient = false;
    } else {
      std::cerr << "usage: skyfarm-worker bench lut-clouds [--out DIR] [--spp N] [--octaves N] [--octave-abc A B C] "
                   "[--octaves-only] [--no-ambient]\n";
      return 2;
    }
  }
  fs::create_directories(dir);
  std::ofstream csv(dir / "lut_clouds.csv");
  csv << "scene,altitude_m,sun_zenith_deg,region,pixels,mean_luminance_rel_error,median_pixel_rel_error,reference_rel_error,lut_seconds,"
         "path_seconds\n";
  for (const char* scene : kScenes)
    for (const double altitude : kAltitudes)
      for (const double sun_zenith : kSunZeniths) {
        CloudFrame lut, path;
        try {
          lut = render_frame(scene, sun_zenith, altitude, true, 1, options);
          path = reference(scene, sun_zenith, altitude, spp, dir);
        } catch (const std::exception& e) {
          std::cout << nlohmann::json{{"bench", "lut_clouds"}, {"scene", scene}, {"skipped", e.what()}}.dump()
                    << std::endl;
          break;
        }
        {  // the LUT frame beside the reference, for a closer look
          std::ofstream out(dir / (std::string("lut_") + scene + "_sun" + std::to_string(static_cast<int>(sun_zenith)) +
                                   "_alt" + std::to_string(static_cast<int>(altitude)) + ".bin"),
                            std::ios::binary);
          out.write(reinterpret_cast<const char*>(lut.Y.data()), static_cast<std::streamsize>(lut.Y.size() * 4));
          out.write(reinterpret_cast<const char*>(lut.T_cloud.data()),
                    static_cast<std::streamsize>(lut.T_cloud.size() * 4));
        }
        Region cloud, gap, all;
        const double cos_sun_pixel = std::cos(10.0 * kDeg);
        for (int y = 0; y < kHeight; ++y) {
          const double zenith = (y + 0.5) * 180.0 / kHeight;
          const double w = std::sin(zenith * kDeg);  // solid angle
          for (int x = 0; x < kWidth; ++x) {
            const double azimuth = (x + 0.5) * 360.0 / kWidth;
            const double cos_to_sun =
                std::cos(zenith * kDeg) * std::cos(sun_zenith * kDeg) +
                std::sin(zenith * kDeg) * std::sin(sun_zenith * kDeg) * std::cos((azimuth - 180.0) * kDeg);
            if (cos_to_sun > cos_sun_pixel) continue;
            const std::size_t i = static_cast<std::size_t>(y * kWidth + x);
            const auto add = [&](Region& r) {
              r.w_lut += w * lut.Y[i];
              r.w_path += w * path.Y[i];
              r.w_var += w * w * path.variance[i];
              r.w += w;
              ++r.pixels;
              if (path.Y[i] > 0.0f) r.ratios.push_back(static_cast<double>(lut.Y[i]) / path.Y[i]);
            };
            add(all);
            const double T = lut.T_cloud[i];
            if (T < 0.5) add(cloud);
            if (altitude == 0.0 && zenith < 90.0 && T > 0.95) add(gap);
          }
        }
        const auto report = [&](const char* region, Region& r) {
          if (r.pixels == 0) return;
          const double median = r.median_error();
          csv << scene << "," << altitude << "," << sun_zenith << "," << region << "," << r.pixels << ","
              << r.rel_error() << "," << median << "," << r.ref_error() << "," << lut.seconds << "," << path.seconds << "\n";
          std::cout << nlohmann::json{{"bench", "lut_clouds"},      {"scene", scene},
                                      {"altitude_m", altitude},     {"sun_zenith_deg", sun_zenith},
                                      {"region", region},           {"pixels", r.pixels},
                                      {"mean_luminance_rel_error", r.rel_error()},
                                      {"median_pixel_rel_error", median},
                                      {"reference_rel_error", r.ref_error()},
                                      {"lut_seconds", lut.seconds}, {"path_seconds", path.seconds}}
                           .dump()
                    << std::endl;
        };
        report(altitude == 0.0 ? "cloud_bases" : "cloud_tops", cloud);
        report("clear_gaps", gap);
        report("whole_frame", all);
      }
  return 0;
}

}  // namespace skyfarm
