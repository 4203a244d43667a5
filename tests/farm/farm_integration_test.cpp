// The render farm end to end on loopback: a real skyfarm-server,
// real skyfarm-worker processes, HTTP from a client.  Every test is bounded
// in time.  The final EXR must be byte-identical to `skyfarm-worker render`
// of the same request, whatever happened on the way.
#include <gtest/gtest.h>

#include <cstdlib>

#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

constexpr const char* kRequest = R"({
  "sun": {"zenith_deg": 55, "azimuth_deg": 200},
  "camera": {"projection": "equirectangular", "width": 128, "height": 64},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 64},
  "output": {"half": false},
  "seed": 11
})";

fs::path fresh_dir(const std::string& name) { return testing::fresh_dir("skyfarm_farm", name); }

// The local render of kRequest (computed once).
const std::string& reference_exr() {
  static const std::string bytes = testing::local_render_exr(kRequest, fresh_dir("reference"));
  return bytes;
}

TEST(Farm, SubmitPollDownloadEqualsLocalRender) {
  const fs::path dir = fresh_dir("basic");
  FarmServer server(dir / "data", 2);
  ASSERT_TRUE(server.ok()) << server.log();
  auto client = server.client();
  const auto res = client.Post("/v1/renders", kRequest, "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const std::string id = nlohmann::json::parse(res->body)["id"];
  EXPECT_EQ(res->get_header_value("Location"), "/v1/renders/" + id);
  const auto status = server.wait(id, std::chrono::seconds(60));
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(status["progress"]["fraction"], 1.0);
  EXPECT_FALSE(status["workers"].empty());
  EXPECT_EQ(server.download(id, "image.exr"), reference_exr());
  EXPECT_FALSE(server.download(id, "image.png").empty());
  // The same request again: answered from the result cache.
  const auto again = client.Post("/v1/renders", kRequest, "application/json");
  ASSERT_TRUE(again);
  EXPECT_EQ(nlohmann::json::parse(again->body)["id"], id);
}

TEST(Farm, OneOrThreeWorkersGiveTheSameBytes) {
  for (int workers : {1, 3}) {
    const fs::path dir = fresh_dir("workers" + std::to_string(workers));
    FarmServer server(dir / "data", workers);
    ASSERT_TRUE(server.ok()) << server.log();
    const std::string id = server.submit(kRequest);
    ASSERT_FALSE(id.empty());
    ASSERT_EQ(server.wait(id, std::chrono::seconds(90))["state"], "done");
    EXPECT_EQ(server.download(id, "image.exr"), reference_exr()) << workers << " workers";
  }
}

// A ground that is a material renders on the farm with the bytes of a local
// render, the status's plan names its model, and the LUT method answers it
// with the material's white-sky albedo.
TEST(Farm, MaterialGroundEqualsLocalRender) {
  constexpr const char* kLake = R"({
    "sun": {"zenith_deg": 84, "azimuth_deg": 270},
    "location": {"altitude_m": 3},
    "camera": {"projection": "equirectangular", "width": 64, "height": 32, "yaw_deg": 270},
    "atmosphere": {"ground": {"material": {"name": "water", "roughness": 0.05}}},
    "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 16},
    "output": {"half": false},
    "seed": 5
  })";
  const fs::path dir = fresh_dir("material_ground");
  const std::string local = testing::local_render_exr(kLake, fresh_dir("material_ground_local"));
  ASSERT_FALSE(local.empty());
  FarmServer server(dir / "data", 2);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string id = server.submit(kLake);
  ASSERT_FALSE(id.empty());
  const auto status = server.wait(id, std::chrono::seconds(90));
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(status["plan"]["ground"]["material"], "water");
  EXPECT_EQ(status["plan"]["ground"]["model"], "multiple_bounce_dielectric");
  EXPECT_EQ(server.download(id, "image.exr"), local);

  std::string lut = kLake;
  lut.replace(lut.find(R"("seed")"), 0, R"("method": "lut", )");
  const std::string lut_id = server.submit(lut);
  ASSERT_FALSE(lut_id.empty());
  EXPECT_EQ(server.wait(lut_id, std::chrono::seconds(90))["state"], "done");
}

TEST(Farm, KilledWorkerLosesNothing) {
  const fs::path dir = fresh_dir("kill");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  const pid_t a = testing::start_worker(server, dir / "a.log");
  const pid_t b = testing::start_worker(server, dir / "b.log");
  const std::string id = server.submit(kRequest);
  ASSERT_FALSE(id.empty());
  // Wait until the job is under way, then SIGKILL one worker.
  for (int i = 0; i < 200 && server.status(id)["progress"]["units_done"].get<int>() < 3; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  testing::kill_and_wait(a, SIGKILL);
  const auto status = server.wait(id, std::chrono::seconds(90));
  testing::kill_and_wait(b, SIGTERM);
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(server.download(id, "image.exr"), reference_exr());
}

TEST(Farm, HungWorkerUnitsAreRequeued) {
  const fs::path dir = fresh_dir("hung");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  const pid_t hung = testing::start_worker(server, dir / "hung.log");
  const std::string id = server.submit(kRequest);
  ASSERT_FALSE(id.empty());
  for (int i = 0; i < 200 && server.status(id)["state"] != "running"; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(hung, SIGSTOP);  // alive but silent: no heartbeats, no results
  const pid_t healthy = testing::start_worker(server, dir / "healthy.log");
  const auto status = server.wait(id, std::chrono::seconds(90));
  ::kill(hung, SIGCONT);
  testing::kill_and_wait(hung, SIGKILL);
  testing::kill_and_wait(healthy, SIGTERM);
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(server.download(id, "image.exr"), reference_exr());
}

TEST(Farm, ServerKilledMidJobResumesWithIdenticalBytes) {
  const fs::path dir = fresh_dir("restart");
  std::string id;
  {
    FarmServer server(dir / "data", 2);
    ASSERT_TRUE(server.ok()) << server.log();
    id = server.submit(kRequest);
    ASSERT_FALSE(id.empty());
    for (int i = 0; i < 400 && server.status(id)["progress"]["units_done"].get<int>() < 10; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    server.kill_now();  // SIGKILL: no chance to tidy up
  }
  // Orphaned local workers notice the lost server and keep retrying; the new
  // server brings its own.
  FarmServer restarted(dir / "data", 2);
  ASSERT_TRUE(restarted.ok()) << restarted.log();
  const auto status = restarted.wait(id, std::chrono::seconds(90));
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(restarted.download(id, "image.exr"), reference_exr());
}

TEST(Farm, CancelStopsTheJobAndFreesTheWorkers) {
  const fs::path dir = fresh_dir("cancel");
  FarmServer server(dir / "data", 2);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string big = R"({"sun": {"zenith_deg": 30, "azimuth_deg": 0},
    "camera": {"projection": "equirectangular", "width": 512, "height": 256},
    "quality": {"samples_per_pixel": 4096}})";
  const std::string id = server.submit(big);
  ASSERT_FALSE(id.empty());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  auto client = server.client();
  const auto res = client.Delete(("/v1/renders/" + id).c_str());
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 202);
  EXPECT_EQ(server.wait(id, std::chrono::seconds(10))["state"], "cancelled");
  // The workers are free: a small job finishes promptly.
  const std::string small = server.submit(kRequest);
  ASSERT_EQ(server.wait(small, std::chrono::seconds(60))["state"], "done");
}

TEST(Farm, BadRequestsGetProblemJsonAndTheServerStaysHealthy) {
  const fs::path dir = fresh_dir("bad");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  auto client = server.client();
  const std::vector<std::string> bodies = {"{", "[]", "null", R"({"camera": 3})",
                                           R"({"camera": {"projection": "equirectangular", "width": -3}})",
                                           std::string(10000, '['), R"({"seed": -1, "camera": {}})"};
  for (const auto& body : bodies) {
    const auto res = client.Post("/v1/renders", body, "application/json");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status / 100, 4) << body.substr(0, 40);
    EXPECT_NE(res->get_header_value("Content-Type").find("application/problem+json"), std::string::npos);
  }
  for (const char* path : {"/v1/renders/..%2Fetc", "/v1/renders/nope", "/v1/renders/nope/image.exr"}) {
    const auto res = client.Get(path);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status / 100, 4) << path;
  }
  const auto health = client.Get("/healthz");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
}

}  // namespace
}  // namespace skyfarm
