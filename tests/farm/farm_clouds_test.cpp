// Clouds on the farm: a cumulus layer drifting in a west wind renders with
// the bytes of `skyfarm-worker render` through one worker, three, and a
// worker killed mid-job (the procedural shapes and every random number are
// pure functions of the request); the status's plan names the layer; and a
// later time of the same request moves the clouds (a timelapse's frames
// differ as the time does).
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdio>

#include "common/image/exr_writer.h"

#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

constexpr const char* kCumulus = R"({
  "location": {"latitude_deg": 48.8566, "longitude_deg": 2.3522},
  "time": "2026-07-15T14:00:00Z",
  "camera": {"projection": "fisheye", "width": 48, "height": 48},
  "atmosphere": {"ground_albedo": 0.15},
  "clouds": {"layers": [{"type": "cumulus", "coverage": 0.4, "optical_depth": 8, "seed": 3,
                         "wind": {"speed_m_s": 15, "from_deg": 270}}]},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 16},
  "output": {"half": false},
  "seed": 9
})";

fs::path fresh_dir(const std::string& name) { return testing::fresh_dir("skyfarm_farm_clouds", name); }

const std::string& reference_exr() {
  static const std::string bytes = testing::local_render_exr(kCumulus, fresh_dir("reference"));
  return bytes;
}

TEST(FarmClouds, OneOrThreeWorkersGiveTheLocalBytes) {
  ASSERT_FALSE(reference_exr().empty());
  for (int workers : {1, 3}) {
    const fs::path dir = fresh_dir("workers" + std::to_string(workers));
    FarmServer server(dir / "data", workers);
    ASSERT_TRUE(server.ok()) << server.log();
    const std::string id = server.submit(kCumulus);
    ASSERT_FALSE(id.empty());
    const auto status = server.wait(id, std::chrono::seconds(120));
    ASSERT_EQ(status["state"], "done") << status.dump();
    EXPECT_EQ(status["plan"]["clouds"]["layers"], 1) << status["plan"].dump();
    EXPECT_EQ(server.download(id, "image.exr"), reference_exr()) << workers << " workers";
  }
}

TEST(FarmClouds, AKilledWorkerLosesNothing) {
  ASSERT_FALSE(reference_exr().empty());
  const fs::path dir = fresh_dir("kill");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  const pid_t a = testing::start_worker(server, dir / "a.log");
  const pid_t b = testing::start_worker(server, dir / "b.log");
  const std::string id = server.submit(kCumulus);
  ASSERT_FALSE(id.empty());
  for (int i = 0; i < 400 && server.status(id)["progress"]["units_done"].get<int>() < 1; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  testing::kill_and_wait(a, SIGKILL);
  const auto status = server.wait(id, std::chrono::seconds(120));
  testing::kill_and_wait(b, SIGTERM);
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(server.download(id, "image.exr"), reference_exr());
}

// The mean relative difference of every channel of two EXR files.
double relative_difference(const fs::path& a, const fs::path& b) {
  const ExrFile x = read_exr(a), y = read_exr(b);
  double diff = 0.0, sum = 0.0;
  for (const auto& [name, channel] : x.channels) {
    const auto& other = y.channels.at(name).values;
    for (std::size_t i = 0; i < channel.values.size(); ++i) {
      diff += std::abs(channel.values[i] - other[i]);
      sum += std::abs(channel.values[i]);
    }
  }
  return diff / sum;
}

// Ten minutes later a 15 m/s wind has carried the clouds 9 km east (three
// times their features' size): the frame changes far more than the same
// pair of times in a calm, where only the sun has moved.  The LUT method,
// free of noise, shows it with one pass.
TEST(FarmClouds, TheWindMovesTheCloudsBetweenFrames) {
  auto frame = [](bool windy, bool later) {
    std::string r = kCumulus;
    const std::string gust = "\"speed_m_s\": 15";
    if (!windy) r.replace(r.find(gust), gust.size(), "\"speed_m_s\": 0");
    if (later) r.replace(r.find("14:00:00Z"), 9, "14:10:00Z");
    r.replace(r.rfind("\"seed\""), 0, "\"method\": \"lut\", ");
    const fs::path dir = fresh_dir(std::string(windy ? "windy" : "calm") + (later ? "_later" : ""));
    EXPECT_FALSE(testing::local_render_exr(r, dir).empty());
    return dir / "local.exr";
  };
  const double windy = relative_difference(frame(true, false), frame(true, true));
  const double calm = relative_difference(frame(false, false), frame(false, true));
  std::printf("ten minutes apart: %.3f relative difference in wind, %.3f in a calm\n", windy, calm);
  EXPECT_GT(windy, 2.0 * calm);
}

}  // namespace
}  // namespace skyfarm
