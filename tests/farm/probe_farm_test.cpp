// POST /v1/sky/radiance with the path tracer through the real farm: a real
// skyfarm-server, its local workers or external skyfarm-worker
// processes, HTTP from a client.  The answer is byte for byte the compact
// JSON of `skyfarm-worker probe` of the same body, whatever the number of
// workers and when one is killed; no worker -> 503; too slow -> 504 and the
// workers are free again; the server counts probes in /metrics.
#include <gtest/gtest.h>

#include <cstdio>
#include <future>

#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

// 2 directions x 2 wavelengths x 40000 samples: 4 units of one pair each.
constexpr const char* kProbe = R"({"sun": {"zenith_deg": 50, "azimuth_deg": 100},
  "atmosphere": {"preset": "earth_clear"},
  "directions": [{"zenith_deg": 10, "azimuth_deg": 0}, {"zenith_deg": 80, "azimuth_deg": 280}],
  "wavelengths_nm": [500, 650], "samples": 40000, "seed": 9})";

// 1 x 2 x 300000: 10 units.
constexpr const char* kLongerProbe = R"({"sun": {"zenith_deg": 50, "azimuth_deg": 100},
  "atmosphere": {"preset": "earth_clear"}, "directions": [{"zenith_deg": 60, "azimuth_deg": 90}],
  "wavelengths_nm": [600, 700], "samples": 300000, "seed": 4})";

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_probe_farm_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// `skyfarm-worker probe` of `body`, as compact JSON ("" on failure).
std::string cli_answer(const std::string& body) {
  const fs::path dir = fresh_dir("cli");
  std::ofstream(dir / "probe.json") << body;
  const std::string cmd = std::string(SKYFARM_WORKER_BINARY) + " probe " + (dir / "probe.json").string() +
                          " --threads 2 > " + (dir / "out.json").string() + " 2>/dev/null";
  if (std::system(cmd.c_str()) != 0) return "";
  return nlohmann::json::parse(testing::read_text(dir / "out.json")).dump();
}

// POSTs the probe, retrying while the server has no worker yet (503).
httplib::Result post_probe(const FarmServer& server, const std::string& body) {
  auto client = server.client();
  for (int i = 0;; ++i) {
    auto res = client.Post("/v1/sky/radiance", body, "application/json");
    if (!res || res->status != 503 || i >= 100) return res;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

std::string metrics(const FarmServer& server) {
  auto client = server.client();
  const auto res = client.Get("/metrics");
  return res ? res->body : std::string();
}

TEST(ProbeFarm, OneOrThreeWorkersAnswerTheCliBytes) {
  const std::string expected = cli_answer(kProbe);
  ASSERT_FALSE(expected.empty());
  for (int workers : {1, 3}) {
    const fs::path dir = fresh_dir("workers" + std::to_string(workers));
    FarmServer server(dir / "data", workers);
    ASSERT_TRUE(server.ok()) << server.log();
    const auto res = post_probe(server, kProbe);
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    EXPECT_EQ(res->body, expected) << workers << " workers";
    EXPECT_NE(metrics(server).find("skyfarm_probes_total{outcome=\"done\"} 1\n"), std::string::npos);
  }
}

TEST(ProbeFarm, NoWorkerIs503WithRetryAfter) {
  const fs::path dir = fresh_dir("none");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  auto client = server.client();
  const auto res = client.Post("/v1/sky/radiance", kProbe, "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 503) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/problem+json");
  EXPECT_EQ(res->get_header_value("Retry-After"), "5");
}

TEST(ProbeFarm, KilledWorkerLosesNothing) {
  const std::string expected = cli_answer(kLongerProbe);
  ASSERT_FALSE(expected.empty());
  const fs::path dir = fresh_dir("kill");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  const pid_t a = testing::start_worker(server, dir / "a.log");
  const pid_t b = testing::start_worker(server, dir / "b.log");
  auto client = server.client();
  for (int i = 0; i < 200; ++i) {  // both joined
    const auto res = client.Get("/v1/workers");
    if (res && nlohmann::json::parse(res->body)["workers"].size() == 2) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  auto answer = std::async(std::launch::async, [&] { return post_probe(server, kLongerProbe); });
  std::this_thread::sleep_for(std::chrono::milliseconds(400));  // both are tracing units
  testing::kill_and_wait(a, SIGKILL);
  const auto res = answer.get();
  testing::kill_and_wait(b, SIGTERM);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->body, expected);
}

TEST(ProbeFarm, SlowProbeIs504AndTheWorkersAreFreedForTheNext) {
  const fs::path dir = fresh_dir("timeout");
  FarmServer server(dir / "data", 1, "tcp://127.0.0.1:*", {"--probe-timeout", "1"});
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string slow = R"({"sun": {"zenith_deg": 30, "azimuth_deg": 0},
    "directions": [{"zenith_deg": 0, "azimuth_deg": 0}], "wavelengths_nm": [550], "samples": 100000000})";
  const auto res = post_probe(server, slow);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 504) << res->body;
  EXPECT_NE(res->body.find("urn:skyfarm:problem:probe-timeout"), std::string::npos) << res->body;
  const std::string text = metrics(server);
  EXPECT_NE(text.find("skyfarm_probes_total{outcome=\"timeout\"} 1\n"), std::string::npos) << text;
  // The cancelled units leave the worker's queue: a small probe is answered.
  const std::string small = R"({"sun": {"zenith_deg": 30, "azimuth_deg": 0},
    "directions": [{"zenith_deg": 0, "azimuth_deg": 0}], "wavelengths_nm": [550], "samples": 1000})";
  const auto next = post_probe(server, small);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->status, 200) << next->body;
}

TEST(ProbeFarm, BadCacheFlagExitsWithTwoNamingTheFlag) {
  const fs::path dir = fresh_dir("flag");
  const std::string cmd = std::string(SKYFARM_SERVER_BINARY) + " --sky-cache-mb lots --data-dir " +
                          (dir / "data").string() + " > " + (dir / "out.txt").string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_NE(testing::read_text(dir / "out.txt").find("--sky-cache-mb: invalid value 'lots'"), std::string::npos);
}

}  // namespace
}  // namespace skyfarm
