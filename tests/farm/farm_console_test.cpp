// The routes the web console uses, on a real farm (skyfarm-server with two
// local workers): POST /v1/workers/{id}/drain stops dispatch to that worker
// (a render then runs on the other alone; GET /v1/workers says "draining")
// and .../resume undoes it; 404 for a worker that is not connected.  The
// list carries each render's name and request; image.png?width=N is the
// final PNG scaled down (cached, with its own ETag; a bad width is a 400
// naming it).
#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "common/image/png_writer.h"
#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

fs::path fresh_dir(const std::string& name) { return testing::fresh_dir("skyfarm_farm_console", name); }

nlohmann::json workers_of(const FarmServer& server) {
  const auto res = server.client().Get("/v1/workers");
  return res && res->status == 200 ? nlohmann::json::parse(res->body)["workers"] : nlohmann::json::array();
}

nlohmann::json worker(const FarmServer& server, const std::string& id) {
  for (const nlohmann::json& w : workers_of(server))
    if (w["id"] == id) return w;
  return nullptr;
}

TEST(FarmConsole, ADrainedWorkerGetsNoUnitsAndResumeUndoesIt) {
  const fs::path dir = fresh_dir("drain");
  FarmServer server(dir / "data", 2);
  ASSERT_TRUE(server.ok()) << server.log();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (workers_of(server).size() < 2 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const nlohmann::json workers = workers_of(server);
  ASSERT_EQ(workers.size(), 2u) << server.log();
  const std::string drained = workers[0]["id"], other = workers[1]["id"];
  EXPECT_EQ(workers[0]["draining"], false);

  auto client = server.client();
  const auto unknown = client.Post("/v1/workers/nobody/drain", "", "application/json");
  ASSERT_TRUE(unknown);
  EXPECT_EQ(unknown->status, 404) << unknown->body;
  const auto drain = client.Post(("/v1/workers/" + drained + "/drain").c_str(), "", "application/json");
  ASSERT_TRUE(drain);
  ASSERT_EQ(drain->status, 200) << drain->body;
  EXPECT_EQ(nlohmann::json::parse(drain->body)["draining"], true);
  EXPECT_EQ(worker(server, drained)["draining"], true);
  EXPECT_EQ(worker(server, other)["draining"], false);
  const int drained_units_before = worker(server, drained)["units_done"];

  // 64 units (8 tiles x 8 passes) while one worker is drained: all go to the other.
  const std::string id = server.submit(R"({"name": "drained farm",
    "sun": {"zenith_deg": 60, "azimuth_deg": 200},
    "camera": {"projection": "equirectangular", "width": 64, "height": 32},
    "quality": {"samples_per_pixel": 8}})");
  ASSERT_FALSE(id.empty()) << server.log();
  const nlohmann::json status = server.wait(id, std::chrono::seconds(60));
  ASSERT_EQ(status["state"], "done") << status.dump();
  ASSERT_EQ(status["workers"].size(), 1u) << status["workers"].dump();
  EXPECT_EQ(status["workers"][0]["id"], other);
  EXPECT_EQ(worker(server, drained)["units_done"], drained_units_before);
  EXPECT_EQ(status["name"], "drained farm");
  EXPECT_EQ(status["progress"]["samples_per_pixel"], 8);
  EXPECT_EQ(status["progress"]["samples_per_pixel_target"], 8);

  // The list: the name and what it asked for.
  const auto list = client.Get("/v1/renders");
  ASSERT_TRUE(list && list->status == 200);
  const nlohmann::json entry = nlohmann::json::parse(list->body)["renders"][0];
  EXPECT_EQ(entry["name"], "drained farm");
  EXPECT_EQ(entry["request"]["sun"]["zenith_deg"], 60);
  EXPECT_EQ(entry["request"]["camera"]["width"], 64);

  const auto resume = client.Post(("/v1/workers/" + drained + "/resume").c_str(), "", "application/json");
  ASSERT_TRUE(resume);
  ASSERT_EQ(resume->status, 200) << resume->body;
  EXPECT_EQ(nlohmann::json::parse(resume->body)["draining"], false);
  EXPECT_EQ(worker(server, drained)["draining"], false);

  // The thumbnail of the final PNG: 16 px wide, the aspect kept.
  const auto thumb = client.Get(("/v1/renders/" + id + "/image.png?width=16").c_str());
  ASSERT_TRUE(thumb);
  ASSERT_EQ(thumb->status, 200) << thumb->body;
  EXPECT_EQ(thumb->get_header_value("Content-Type"), "image/png");
  const std::string etag = thumb->get_header_value("ETag");
  EXPECT_TRUE(etag.ends_with("-w16\"")) << etag;
  const fs::path file = dir / "thumb.png";
  std::ofstream(file, std::ios::binary) << thumb->body;
  const PngFile png = read_png(file);
  EXPECT_EQ(png.width, 16);
  EXPECT_EQ(png.height, 8);
  const auto again = client.Get(("/v1/renders/" + id + "/image.png?width=16").c_str(), {{"If-None-Match", etag}});
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 304);
  for (const char* bad : {"0", "abc", "2000"}) {
    const auto res = client.Get(("/v1/renders/" + id + "/image.png?width=" + bad).c_str());
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 400) << bad;
    EXPECT_NE(res->body.find("width"), std::string::npos) << res->body;
  }
}

}  // namespace
}  // namespace skyfarm
