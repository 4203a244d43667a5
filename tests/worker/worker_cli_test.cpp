// skyfarm-worker as a user runs it: render to EXR and PNG, probe to JSON,
// clear errors for bad input.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>
#include <cmath>
#include <string>
#include <vector>
#include <sys/wait.h>

#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout and stderr together
};

CommandResult run_worker(const std::string& args, const std::string& stdin_text = "") {
  const fs::path tmp = fs::temp_directory_path() / ("skyfarm_cli_" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  std::string cmd = std::string(SKYFARM_WORKER_BINARY) + " " + args;
  if (!stdin_text.empty()) {
    std::ofstream(tmp / "stdin.json") << stdin_text;
    cmd += " < " + (tmp / "stdin.json").string();
  }
  cmd += " 2>&1";
  CommandResult r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

constexpr const char* kSmallRequest = R"({
  "location": {"latitude_deg": 42.44, "longitude_deg": -76.48, "altitude_m": 250},
  "time": "2013-05-27T19:30:00-04:00",
  "camera": {"projection": "equirectangular", "width": 32, "height": 16},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 4},
  "output": {"half": false, "spectral_channels": true, "error_layer": true}
})";

TEST(WorkerCli, RenderWritesExrAndPngWithMetadata) {
  const fs::path dir = temp_dir("render");
  std::ofstream(dir / "request.json") << kSmallRequest;
  const CommandResult r = run_worker("render " + (dir / "request.json").string() + " -o " + (dir / "sky.exr").string() + " --png " +
                    (dir / "sky.png").string() + " --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("paths/s"), std::string::npos) << r.out;
  const ExrFile exr = read_exr(dir / "sky.exr");
  EXPECT_EQ(exr.width, 32);
  EXPECT_EQ(exr.height, 16);
  EXPECT_TRUE(exr.channels.count("R") && exr.channels.count("G") && exr.channels.count("B"));
  EXPECT_TRUE(exr.channels.count(kExrErrorChannel));
  EXPECT_EQ(exr.channels.count(spectral_channel_name(477.5)), 1u);  // band centre of 360-595 nm
  EXPECT_TRUE(exr.chromaticities.has_value());
  EXPECT_EQ(exr.string_attributes.count("skyfarm:request"), 1u);
  // The error estimate, of the luminance and per channel, is in the header.
  for (const char* key : {"skyfarm:estimated_relative_rms", "skyfarm:estimated_relative_rms_r",
                          "skyfarm:estimated_relative_rms_g", "skyfarm:estimated_relative_rms_b"}) {
    ASSERT_EQ(exr.number_attributes.count(key), 1u) << key;
    EXPECT_GT(exr.number_attributes.at(key), 0.0) << key;
  }
  EXPECT_NE(r.out.find("(R "), std::string::npos) << r.out;
  // Linear Rec.709 may be negative for colours outside its gamut; the
  // luminance (Rec.709 Y weights) may not.
  double luminance_sum = 0.0;
  const auto& R = exr.channels.at("R").values;
  const auto& G = exr.channels.at("G").values;
  const auto& B = exr.channels.at("B").values;
  for (std::size_t i = 0; i < G.size(); ++i) {
    ASSERT_TRUE(std::isfinite(R[i]) && std::isfinite(G[i]) && std::isfinite(B[i])) << i;
    const double Y = 0.2126 * R[i] + 0.7152 * G[i] + 0.0722 * B[i];
    ASSERT_GE(Y, -1e-3 * std::abs(G[i]) - 1e-9) << i;
    luminance_sum += Y;
  }
  EXPECT_GT(luminance_sum, 0.0);
  const PngFile png = read_png(dir / "sky.png");
  EXPECT_EQ(png.width, 32);
  EXPECT_EQ(png.height, 16);
}

TEST(WorkerCli, ProbePrintsRadianceJsonFromStdin) {
  const CommandResult r = run_worker("probe - --threads 2", R"({
    "sun": {"zenith_deg": 40, "azimuth_deg": 180},
    "atmosphere": {"preset": "earth_clear"},
    "directions": [{"zenith_deg": 0, "azimuth_deg": 0}, {"zenith_deg": 70, "azimuth_deg": 180}],
    "wavelengths_nm": [450, 650], "samples": 512, "seed": 3})");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["units"], "W m-2 sr-1 nm-1");
  ASSERT_EQ(j["radiance"].size(), 2u);
  ASSERT_EQ(j["radiance"][0].size(), 2u);
  ASSERT_EQ(j["standard_error"][1].size(), 2u);
  // Blue sky: more radiance at 450 than at 650 nm looking up.
  const double blue = j["radiance"][0][0], red = j["radiance"][0][1];
  EXPECT_GT(blue, red);
  // Same request, same answer (deterministic).
  const CommandResult again = run_worker("probe - --threads 1", R"({
    "sun": {"zenith_deg": 40, "azimuth_deg": 180},
    "atmosphere": {"preset": "earth_clear"},
    "directions": [{"zenith_deg": 0, "azimuth_deg": 0}, {"zenith_deg": 70, "azimuth_deg": 180}],
    "wavelengths_nm": [450, 650], "samples": 512, "seed": 3})");
  EXPECT_EQ(nlohmann::json::parse(again.out)["radiance"], j["radiance"]);
}

TEST(WorkerCli, BadRequestNamesTheFieldAndWritesNothing) {
  const fs::path dir = temp_dir("bad");
  std::ofstream(dir / "bad.json") << R"({"camera": {"projection": "equirectangular", "width": -3}, "sun": {"zenith_deg": 10, "azimuth_deg": 0}})";
  const CommandResult r = run_worker("render " + (dir / "bad.json").string() + " -o " + (dir / "out.exr").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find("camera.width: must be an integer in [1, 16384], got -3"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

TEST(WorkerCli, UsageErrorsAreClear) {
  EXPECT_EQ(run_worker("render").exit_code, 2);
  EXPECT_EQ(run_worker("render x.json").exit_code, 2);  // no -o
  const CommandResult missing = run_worker("render /nonexistent/request.json -o /tmp/x.exr");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.out.find("cannot open"), std::string::npos);
  EXPECT_EQ(run_worker("frobnicate").exit_code, 2);
  EXPECT_EQ(run_worker("--version").exit_code, 0);
}

TEST(WorkerCli, UnwritableOutputIsAClearError) {
  const fs::path dir = temp_dir("unwritable");
  std::ofstream(dir / "request.json") << kSmallRequest;
  const CommandResult r = run_worker("render " + (dir / "request.json").string() + " -o /nonexistent-dir/sky.exr");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("/nonexistent-dir/sky.exr"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace skyfarm

namespace skyfarm {
namespace {

// The efficiency bench prints one JSON line per sun, with a finite, positive
// efficiency and no discarded path.
TEST(WorkerCli, BenchEfficiencyPrintsOneLinePerSun) {
  const CommandResult r = run_worker("bench efficiency --samples 4 --sun-zenith 30 --sun-zenith 96");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::istringstream lines(r.out);
  int n = 0;
  for (std::string line; std::getline(lines, line);) {
    const auto j = nlohmann::json::parse(line);
    EXPECT_EQ(j["bench"], "efficiency");
    EXPECT_GT(j["efficiency"].get<double>(), 0.0) << line;
    EXPECT_GT(j["relative_std_per_path"].get<double>(), 0.0) << line;
    EXPECT_EQ(j["nonfinite"], 0) << line;
    ++n;
  }
  EXPECT_EQ(n, 2);
  EXPECT_EQ(run_worker("bench efficiency --bogus").exit_code, 2);
}

// The sky-accuracy bench is wired (a full run traces minutes: README,
// "Accuracy"): an unknown flag and a flag without its value are usage errors.
TEST(WorkerCli, BenchSkyAccuracyRejectsBadFlags) {
  const CommandResult bogus = run_worker("bench sky-accuracy --bogus 1");
  EXPECT_EQ(bogus.exit_code, 2);
  EXPECT_NE(bogus.out.find("sky-accuracy [--reference FILE]"), std::string::npos) << bogus.out;
  EXPECT_EQ(run_worker("bench sky-accuracy --cases").exit_code, 2);
}

// The objects bench, its paths part once: a line per view and scene, the
// balls' line with its ratio to the empty sky; the mirror part small, its
// error falling from the first pass to the last.
TEST(WorkerCli, BenchObjectsPrintsPathsAndMirrorError) {
  const CommandResult paths = run_worker("bench objects paths --repeat 1");
  ASSERT_EQ(paths.exit_code, 0) << paths.out;
  std::istringstream lines(paths.out);
  int n = 0;
  for (std::string line; std::getline(lines, line); ++n) {
    const auto j = nlohmann::json::parse(line);
    EXPECT_EQ(j["bench"], "objects_paths_per_second_per_core");
    EXPECT_GT(j["median"].get<double>(), 0.0) << line;
    EXPECT_EQ(j.contains("relative_to_empty"), j["scene"] == "reference_balls") << line;
  }
  EXPECT_EQ(n, 4);

  const CommandResult mirror = run_worker("bench objects mirror --passes 4 --seeds 1 --reference-passes 8");
  ASSERT_EQ(mirror.exit_code, 0) << mirror.out;
  std::istringstream mirror_lines(mirror.out);
  std::vector<nlohmann::json> errors;
  for (std::string line; std::getline(mirror_lines, line);) {
    const auto j = nlohmann::json::parse(line);
    if (j["bench"] == "objects_mirror_reference") {
      EXPECT_GT(j["mirror_pixels"].get<int>(), 500) << line;
    }
    if (j["bench"] == "objects_mirror_error") errors.push_back(j);
  }
  ASSERT_EQ(errors.size(), 3u) << mirror.out;  // after passes 1, 2 and 4
  EXPECT_GT(errors.front()["median_relative_rms"].get<double>(), errors.back()["median_relative_rms"].get<double>())
      << mirror.out;
  EXPECT_EQ(run_worker("bench objects --bogus").exit_code, 2);
}

}  // namespace
}  // namespace skyfarm

namespace skyfarm {
namespace {

// probe with "method": "lut": deterministic, no standard error, and close to
// the path tracer's answer for the same request (measured 0.3-7 % off the
// horizon with the sun at 30 deg; the bound leaves room for the path
// tracer's 2 % noise at 4096 samples).
TEST(WorkerCli, ProbeWithTheLutAgreesWithThePathTracer) {
  const std::string body = R"({
    "sun": {"zenith_deg": 30, "azimuth_deg": 180},
    "directions": [{"zenith_deg": 0, "azimuth_deg": 0}, {"zenith_deg": 40, "azimuth_deg": 180},
                   {"zenith_deg": 120, "azimuth_deg": 90}],
    "wavelengths_nm": [450, 550, 650], "samples": 4096, "seed": 3, "method": ")";
  const CommandResult lut = run_worker("probe - --threads 2", body + R"(lut"})");
  const CommandResult path = run_worker("probe - --threads 2", body + R"(path"})");
  ASSERT_EQ(lut.exit_code, 0) << lut.out;
  ASSERT_EQ(path.exit_code, 0) << path.out;
  const auto a = nlohmann::json::parse(lut.out), b = nlohmann::json::parse(path.out);
  EXPECT_EQ(a["method"], "lut");
  EXPECT_EQ(a["approximate"], true);
  EXPECT_TRUE(a["standard_error"].is_null());
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t w = 0; w < 3; ++w) {
      const double x = a["radiance"][d][w], y = b["radiance"][d][w];
      EXPECT_NEAR(x / y, 1.0, 0.12) << "direction " << d << ", wavelength " << w;
    }
}

}  // namespace
}  // namespace skyfarm
