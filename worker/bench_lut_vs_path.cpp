#include "worker/bench_lut_vs_path.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "api/render_spec.h"
#include "common/film/image.h"
#include "common/render/local_render.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 36, kHeight = 18, kBatches = 8;
constexpr double kSunZeniths[] = {0, 30, 60, 80, 85, 90, 93, 96};
constexpr double kAltitudes[] = {0.0, 10000.0, 100000.0};

std::string request_json(double sun_zenith, double altitude, const char* method, int spp) {
  return std::string(R"({"sun": {"zenith_deg": )") + std::to_string(sun_zenith) +
         R"(, "azimuth_deg": 180}, "location": {"altitude_m": )" + std::to_string(altitude) +
         R"(}, "camera": {"projection": "equirectangular", "width": 36, "height": 18, "yaw_deg": 180},)"
         R"( "spectral": {"batches": 8}, "quality": {"samples_per_pixel": )" + std::to_string(spp) +
         R"(}, "method": ")" + method + R"(", "output": {"half": false, "spectral_channels": true}, "seed": 77})";
}

// Per pixel: luminance, then the kBatches band means.
struct SkyFrame {
  std::vector<float> values;  // (kBatches + 1) per pixel
  double estimated_error = 0.0;
  double seconds = 0.0;
  float at(int x, int y, int channel) const {
    return values[static_cast<std::size_t>((y * kWidth + x) * (kBatches + 1) + channel)];
  }
};

SkyFrame render_frame(const std::string& json) {
  const RenderSetup setup = make_render_setup(api::render_spec(api::parse_render_request(json)));
  const auto t0 = std::chrono::steady_clock::now();
  const TileRenderer renderer(*setup.scene, *setup.camera, setup.plan);
  ImageLayers layers;
  layers.spectral = SpectralLayout{setup.plan.lambda_min_nm, setup.plan.lambda_max_nm, kBatches};
  Image image(kWidth, kHeight, layers);
  const LocalRenderResult r = render_image(renderer, &image, 0);
  SkyFrame f;
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  f.estimated_error = r.estimated_relative_rms;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      f.values.push_back(static_cast<float>(image.luminance(x, y)));
      for (int b = 0; b < kBatches; ++b) f.values.push_back(image.spectral(x, y, b));
    }
  return f;
}

// The path-traced reference, cached as raw floats plus its estimated error.
SkyFrame reference(double sun_zenith, double altitude, int spp, const fs::path& dir) {
  const fs::path cache = dir / ("path_sun" + std::to_string(static_cast<int>(sun_zenith)) + "_alt" +
                                std::to_string(static_cast<int>(altitude)) + "_spp" + std::to_string(spp) + ".bin");
  SkyFrame f;
  f.values.resize(static_cast<std::size_t>(kWidth * kHeight * (kBatches + 1)));
  if (std::ifstream in(cache, std::ios::binary);
      in && in.read(reinterpret_cast<char*>(f.values.data()), static_cast<std::streamsize>(f.values.size() * 4)) &&
      in.read(reinterpret_cast<char*>(&f.estimated_error), sizeof(double)))
    return f;
  f = render_frame(request_json(sun_zenith, altitude, "path", spp));
  std::ofstream out(cache, std::ios::binary);
  out.write(reinterpret_cast<const char*>(f.values.data()), static_cast<std::streamsize>(f.values.size() * 4));
  out.write(reinterpret_cast<const char*>(&f.estimated_error), sizeof(double));
  return f;
}

struct Comparison {
  double rms_luminance = 0.0, max_luminance = 0.0, worst_zenith = 0.0, worst_azimuth = 0.0;
  std::vector<double> rms_band;
};

// Pixel centre directions of the 36 x 18 equirect (yaw 180: column x looks
// at azimuth (x + 0.5) * 10 deg); the sun's pixels are those within a pixel
// diagonal of its direction.
bool sees_sun(int x, int y, double sun_zenith) {
  const double deg = 3.14159265358979 / 180.0;
  const double zenith = (y + 0.5) * 10.0, azimuth = (x + 0.5) * 10.0;
  const double cos_to_sun = std::cos(zenith * deg) * std::cos(sun_zenith * deg) +
                            std::sin(zenith * deg) * std::sin(sun_zenith * deg) * std::cos((azimuth - 180.0) * deg);
  return cos_to_sun > std::cos(15.0 * deg);
}

Comparison compare(const SkyFrame& lut, const SkyFrame& path, double sun_zenith) {
  Comparison c;
  double y_max = 0.0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (!sees_sun(x, y, sun_zenith)) y_max = std::max<double>(y_max, path.at(x, y, 0));
  std::vector<double> num(kBatches + 1, 0.0), den(kBatches + 1, 0.0);
  for (int y = 0; y < kHeight; ++y) {
    const double zenith = (y + 0.5) * 10.0;
    const double w = std::sin(zenith * 3.14159265358979 / 180.0);  // solid angle
    for (int x = 0; x < kWidth; ++x) {
      if (sees_sun(x, y, sun_zenith)) continue;
      for (int k = 0; k <= kBatches; ++k) {
        const double a = lut.at(x, y, k), b = path.at(x, y, k);
        num[static_cast<std::size_t>(k)] += w * (a - b) * (a - b);
        den[static_cast<std::size_t>(k)] += w * b * b;
      }
      const double b = path.at(x, y, 0);
      if (b > 1e-3 * y_max) {
        const double e = std::abs(lut.at(x, y, 0) - b) / b;
        if (e > c.max_luminance) {
          c.max_luminance = e;
          c.worst_zenith = zenith;
          c.worst_azimuth = (x + 0.5) * 10.0;
        }
      }
    }
  }
  c.rms_luminance = den[0] > 0.0 ? std::sqrt(num[0] / den[0]) : 0.0;
  for (int k = 1; k <= kBatches; ++k)
    c.rms_band.push_back(den[static_cast<std::size_t>(k)] > 0.0
                             ? std::sqrt(num[static_cast<std::size_t>(k)] / den[static_cast<std::size_t>(k)])
                             : 0.0);
  return c;
}

}  // namespace

int run_bench_lut_vs_path(const std::vector<std::string>& args) {
  fs::path dir = "skyfarm-lut-vs-path";
  int spp = 2048;
  for (std::size_t i = 1; i < args.size(); ++i) {  // args[0] is "lut-vs-path"
    if (args[i] == "--out" && i + 1 < args.size()) {
      dir = args[++i];
    } else if (args[i] == "--spp" && i + 1 < args.size()) {
      spp = std::max(16, std::atoi(args[++i].c_str()));
    } else {
      std::cerr << "usage: skyfarm-worker bench lut-vs-path [--out DIR] [--spp N]\n";
      return 2;
    }
  }
  fs::create_directories(dir);
  std::ofstream csv(dir / "lut_vs_path.csv");
  csv << "altitude_m,sun_zenith_deg,luminance_rel_rms,luminance_max_rel,worst_zenith_deg,worst_azimuth_deg,"
         "reference_est_rel_rms,lut_seconds";
  for (int b = 0; b < kBatches; ++b) csv << ",band" << b << "_rel_rms";
  csv << "\n";
  for (const double altitude : kAltitudes) {
    for (const double sun_zenith : kSunZeniths) {
      const SkyFrame path = reference(sun_zenith, altitude, spp, dir);
      const SkyFrame lut = render_frame(request_json(sun_zenith, altitude, "lut", 1));
      const Comparison c = compare(lut, path, sun_zenith);
      csv << altitude << "," << sun_zenith << "," << c.rms_luminance << "," << c.max_luminance << ","
          << c.worst_zenith << "," << c.worst_azimuth << "," << path.estimated_error << "," << lut.seconds;
      for (double e : c.rms_band) csv << "," << e;
      csv << "\n";
      std::cout << nlohmann::json{{"bench", "lut_vs_path"},
                                  {"altitude_m", altitude},
                                  {"sun_zenith_deg", sun_zenith},
                                  {"luminance_rel_rms", c.rms_luminance},
                                  {"luminance_max_rel", c.max_luminance},
                                  {"worst_direction", {{"zenith_deg", c.worst_zenith}, {"azimuth_deg", c.worst_azimuth}}},
                                  {"band_rel_rms", c.rms_band},
                                  {"reference_est_rel_rms", path.estimated_error},
                                  {"lut_seconds", lut.seconds}}
                       .dump()
                << std::endl;
    }
  }
  return 0;
}

}  // namespace skyfarm
