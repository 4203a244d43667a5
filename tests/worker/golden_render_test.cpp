// Golden renders of plain skies: `skyfarm-worker render` of small requests
// (the whole way from request JSON through setup, plan, renderer, merge and
// EXR), each reduced to a 64-bit FNV-1a hash of every channel's float bits.
// A change that is meant to leave these scenes alone (a reorganisation, a new
// capability that they do not use: surfaces, objects, clouds) must keep every
// hash; one that changes the physics on purpose updates them in the same
// commit and says why.  The scenes cover both methods, the three projections,
// the ground, twilight, orbit, aerosols, a custom atmosphere, adaptive
// sampling and the spectral and error layers.
//
// The hashes were taken with the renderer as of 2026-12-03 (x86-64, GCC 12,
// -O2 without -ffast-math); lut_equirect's on 2026-12-07, when the LUT sky
// gained its multiple-scattering bands (the physics changed on purpose:
// tests/common/lut/ measure it against the path tracer).  Every other test
// of the renderer's physics compares against analytic or published values,
// not against these.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>

#include "common/image/exr_writer.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

struct Golden {
  const char* name;
  const char* request;
  std::uint64_t hash;
};

void PrintTo(const Golden& g, std::ostream* os) { *os << g.name; }

// FNV-1a over the size, then each channel's name and float bit patterns (in
// the map's name order).
std::uint64_t image_hash(const ExrFile& exr) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto add = [&h](const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= p[i];
      h *= 0x100000001b3ULL;
    }
  };
  add(&exr.width, sizeof exr.width);
  add(&exr.height, sizeof exr.height);
  for (const auto& [name, channel] : exr.channels) {
    add(name.data(), name.size());
    add(channel.values.data(), channel.values.size() * sizeof(float));
  }
  return h;
}

const Golden kScenes[] = {
    {"sunset_equirect_aerosol",
     R"({"location": {"latitude_deg": 42.44, "longitude_deg": -76.48, "altitude_m": 250},
         "time": "2013-05-27T20:25:00-04:00",
         "camera": {"projection": "equirectangular", "width": 48, "height": 24},
         "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 8}})",
     0x2d1fedda23965129ULL},
    {"noon_fisheye_mountain",
     R"({"location": {"latitude_deg": 48.85, "longitude_deg": 2.35, "altitude_m": 2000},
         "time": "2021-06-21T13:30:00+02:00",
         "camera": {"projection": "fisheye", "width": 32, "height": 32, "pitch_deg": 90},
         "quality": {"samples_per_pixel": 8}})",
     0x2390da6a0be3f784ULL},
    {"twilight_perspective",
     R"({"location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
         "sun": {"zenith_deg": 96, "azimuth_deg": 292},
         "camera": {"projection": "perspective", "width": 40, "height": 20, "yaw_deg": 292, "pitch_deg": 10,
                    "fov_deg": 90},
         "atmosphere": {"preset": "earth_clear", "ozone_du": 350},
         "quality": {"samples_per_pixel": 8}})",
     0x19fe9bbf099f05a7ULL},
    {"orbit_400km",
     R"({"location": {"latitude_deg": 0, "longitude_deg": -30, "altitude_m": 400000},
         "time": "2020-03-20T12:00:00Z",
         "camera": {"projection": "perspective", "width": 32, "height": 18, "yaw_deg": 90, "pitch_deg": -20,
                    "fov_deg": 70},
         "atmosphere": {"preset": "earth", "aerosol": {"optical_depth_550": 0.05}},
         "spectral": {"min_nm": 380, "max_nm": 780, "batches": 4}, "quality": {"samples_per_pixel": 4}})",
     0xa65e4ff1dc2fa8a0ULL},
    {"lut_equirect",
     R"({"location": {"latitude_deg": 35.0, "longitude_deg": 139.0},
         "time": "2022-09-01T17:40:00+09:00", "method": "lut",
         "camera": {"projection": "equirectangular", "width": 64, "height": 32}})",
     0xf94ca127efcec50fULL},
    {"custom_atmosphere_path",
     R"({"location": {"latitude_deg": 45, "longitude_deg": 6},
         "sun": {"zenith_deg": 75, "azimuth_deg": 250},
         "camera": {"projection": "equirectangular", "width": 24, "height": 12},
         "atmosphere": {"preset": "custom", "planet_radius_m": 6360000, "top_altitude_m": 60000,
           "ground_albedo": {"wavelengths_nm": [360, 550, 830], "values": [0.1, 0.2, 0.3]},
           "constituents": [
             {"name": "air", "density": {"type": "exponential", "scale_height_m": 8000},
              "scattering_per_m": {"wavelengths_nm": [360, 440, 550, 680, 830],
                                   "values": [7.387e-5, 3.31e-5, 1.3558e-5, 5.802e-6, 2.614e-6]},
              "phase": {"type": "rayleigh", "depolarization": 0.0279}}]},
         "quality": {"samples_per_pixel": 8}})",
     0x50784bfe2ad77ec3ULL},
    {"adaptive_with_layers",
     R"({"location": {"latitude_deg": -33.9, "longitude_deg": 18.4},
         "time": "2019-12-21T06:10:00+02:00",
         "camera": {"projection": "equirectangular", "width": 32, "height": 16},
         "spectral": {"batches": 2},
         "quality": {"samples_per_pixel": 32, "adaptive": true},
         "output": {"spectral_channels": true, "error_layer": true}})",
     0x22fccabfe6dbff70ULL},
};

class GoldenRender : public ::testing::TestWithParam<Golden> {};

TEST_P(GoldenRender, PixelsAreTheGoldenOnes) {
  const Golden& g = GetParam();
  const fs::path dir = fs::temp_directory_path() / ("skyfarm_golden_" + std::string(g.name) + "_" +
                                                    std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "request.json") << g.request;
  const std::string cmd = std::string(SKYFARM_WORKER_BINARY) + " render " + (dir / "request.json").string() +
                          " -o " + (dir / "out.exr").string() + " --threads 2 > " + (dir / "log.txt").string() +
                          " 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream log_file(dir / "log.txt");
  const std::string log((std::istreambuf_iterator<char>(log_file)), std::istreambuf_iterator<char>());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << log;
  const std::uint64_t hash = image_hash(read_exr(dir / "out.exr"));
  char text[32];
  std::snprintf(text, sizeof text, "0x%016llxULL", static_cast<unsigned long long>(hash));
  EXPECT_EQ(hash, g.hash) << g.name << ": the pixels changed; hash now " << text;
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(PlainSkies, GoldenRender, ::testing::ValuesIn(kScenes),
                         [](const ::testing::TestParamInfo<Golden>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace skyfarm
