// Timelapses end to end on loopback: a real skyfarm-server with its
// local ZeroMQ workers, HTTP from a client.  A 4-frame timelapse finishes with
// its frames in time order, a contact sheet of the documented size and a
// video (when ffmpeg is installed); a bogus ffmpeg leaves only the video out;
// a server killed mid-way is replaced and the timelapse finishes; cancel
// stops every frame; bad requests name the field.  Waits are bounded.
#include <gtest/gtest.h>

#include <unistd.h>

#include "common/image/exr_writer.h"
#include "server/timelapse/timelapse_contact_sheet.h"
#include "server/timelapse/timelapse_video.h"
#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::FarmServer;

// 4 LUT frames of 16 x 8 an hour apart, 2013-05-27 17:00-20:00 EDT in Ithaca.
constexpr const char* kLutTimelapse = R"({
  "location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
  "start": "2013-05-27T17:00:00-04:00", "end": "2013-05-27T20:00:00-04:00", "step_s": 3600,
  "camera": {"projection": "equirectangular", "width": 16, "height": 8},
  "method": "lut", "video_fps": 4
})";

// Four path-traced frames of 32 x 16 (256 samples: about a second on one worker).
std::string slow_timelapse(int samples) {
  return R"({"location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
    "start": "2013-05-27T17:00:00-04:00", "end": "2013-05-27T20:00:00-04:00", "frames": 4,
    "camera": {"projection": "equirectangular", "width": 32, "height": 16},
    "spectral": {"batches": 1}, "quality": {"samples_per_pixel": )" +
         std::to_string(samples) + "}}";
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_tlfarm_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct Answer {
  int status = 0;
  std::string body;
  std::string content_type;
  std::string location;
  nlohmann::json json() const { return nlohmann::json::parse(body, nullptr, false); }
};

Answer get(const FarmServer& server, const std::string& path) {
  auto c = server.client();
  const auto res = c.Get(path.c_str());
  if (!res) return {};
  return {res->status, res->body, res->get_header_value("Content-Type"), res->get_header_value("Location")};
}

Answer post(const FarmServer& server, const std::string& path, const std::string& body) {
  auto c = server.client();
  const auto res = c.Post(path.c_str(), body, "application/json");
  if (!res) return {};
  return {res->status, res->body, res->get_header_value("Content-Type"), res->get_header_value("Location")};
}

// Polls a timelapse until it is in a terminal state (or `timeout` passes).
nlohmann::json wait_timelapse(const FarmServer& server, const std::string& id, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  nlohmann::json s;
  while (std::chrono::steady_clock::now() < deadline) {
    const Answer a = get(server, "/v1/timelapses/" + id);
    if (a.status == 200) {
      s = a.json();
      const std::string state = s["state"];
      if (state == "done" || state == "failed" || state == "cancelled") return s;
    }
    std::this_thread::sleep_for(50ms);
  }
  return s;
}

// Width and height from a PNG's IHDR chunk.
std::pair<int, int> png_size(const std::string& bytes) {
  if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0) return {0, 0};
  auto be32 = [&](std::size_t at) {
    return (static_cast<unsigned char>(bytes[at]) << 24) | (static_cast<unsigned char>(bytes[at + 1]) << 16) |
           (static_cast<unsigned char>(bytes[at + 2]) << 8) | static_cast<unsigned char>(bytes[at + 3]);
  };
  return {static_cast<int>(be32(16)), static_cast<int>(be32(20))};
}

std::string submit_id(const FarmServer& server, const std::string& body) {
  const Answer a = post(server, "/v1/timelapses", body);
  EXPECT_EQ(a.status, 202) << a.body;
  if (a.status != 202) return "";
  const std::string id = a.json()["id"];
  EXPECT_EQ(a.location, "/v1/timelapses/" + id);
  return id;
}

TEST(TimelapseFarm, FourFramesFinishInTimeOrderWithContactSheetAndVideo) {
  const fs::path dir = fresh_dir("basic");
  FarmServer server(dir / "data", 2);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string id = submit_id(server, kLutTimelapse);
  ASSERT_FALSE(id.empty());
  const auto s = wait_timelapse(server, id, 120s);
  ASSERT_EQ(s["state"], "done") << s.dump(1) << server.log();
  EXPECT_EQ(s["progress"]["frames_done"], 4);
  ASSERT_EQ(s["frames"].size(), 4u);
  const char* utc[] = {"2013-05-27T21:00:00Z", "2013-05-27T22:00:00Z", "2013-05-27T23:00:00Z", "2013-05-28T00:00:00Z"};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& f = s["frames"][i];
    EXPECT_EQ(f["index"], i);
    EXPECT_EQ(f["time"], "2013-05-27T" + std::to_string(17 + i) + ":00:00-04:00");
    // The frame's render is a job of its own, with the frame's time in its EXR.
    const std::string render_id = f["render_id"];
    EXPECT_EQ(get(server, "/v1/renders/" + render_id).json()["state"], "done");
    const Answer exr = get(server, "/v1/timelapses/" + id + "/frames/" + std::to_string(i) + ".exr");
    ASSERT_EQ(exr.status, 200);
    EXPECT_EQ(exr.body, server.download(render_id, "image.exr"));
    const fs::path exr_path = dir / ("frame" + std::to_string(i) + ".exr");
    std::ofstream(exr_path, std::ios::binary) << exr.body;
    const auto request = nlohmann::json::parse(read_exr(exr_path).string_attributes.at("skyfarm:request"));
    EXPECT_EQ(request["time"], utc[i]) << "frame " << i;
    const Answer png = get(server, "/v1/timelapses/" + id + "/frames/" + std::to_string(i) + ".png");
    ASSERT_EQ(png.status, 200);
    EXPECT_EQ(png.content_type, "image/png");
    EXPECT_EQ(png_size(png.body), std::make_pair(16, 8));
  }
  // Every frame is listed under /v1/renders too, and the timelapse under /v1/timelapses.
  EXPECT_EQ(get(server, "/v1/renders").json()["total"], 4);
  EXPECT_EQ(get(server, "/v1/timelapses").json()["timelapses"][0]["id"], id);
  EXPECT_EQ(get(server, "/v1/timelapses/" + id + "/frames").json()["frames"].size(), 4u);
  const Answer sheet = get(server, "/v1/timelapses/" + id + "/contact_sheet.png");
  ASSERT_EQ(sheet.status, 200);
  const server::ContactSheetLayout layout = server::contact_sheet_layout(4, 16, 8);
  EXPECT_EQ(png_size(sheet.body), std::make_pair(layout.width, layout.height));
  EXPECT_EQ(png_size(sheet.body), std::make_pair(808, 123)) << "4 cells of 192 px in a row, as documented";

  const Answer video = get(server, "/v1/timelapses/" + id + "/video.mp4");
  if (!server::find_ffmpeg("").path)
    GTEST_SKIP() << "ffmpeg is not installed here: the video assertions are skipped (status says: "
                 << s["video"].dump() << ")";
  EXPECT_EQ(s["video"]["available"], true) << s["video"].dump();
  ASSERT_EQ(video.status, 200) << video.body;
  EXPECT_EQ(video.content_type, "video/mp4");
  EXPECT_EQ(video.body.substr(4, 4), "ftyp");
}

TEST(TimelapseFarm, ABogusFfmpegLeavesOnlyTheVideoOut) {
  const fs::path dir = fresh_dir("noffmpeg");
  FarmServer server(dir / "data", 2, "tcp://127.0.0.1:*", {"--ffmpeg", "/nonexistent/bin/ffmpeg"});
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string id = submit_id(server, kLutTimelapse);
  ASSERT_FALSE(id.empty());
  const auto s = wait_timelapse(server, id, 120s);
  ASSERT_EQ(s["state"], "done") << s.dump(1);
  EXPECT_EQ(s["video"]["available"], false);
  EXPECT_NE(s["video"]["reason"].get<std::string>().find("/nonexistent/bin/ffmpeg"), std::string::npos)
      << s["video"].dump();
  const Answer video = get(server, "/v1/timelapses/" + id + "/video.mp4");
  EXPECT_EQ(video.status, 404);
  EXPECT_EQ(video.content_type, "application/problem+json");
  EXPECT_EQ(get(server, "/v1/timelapses/" + id + "/contact_sheet.png").status, 200);
  EXPECT_EQ(get(server, "/v1/timelapses/" + id + "/frames/3.png").status, 200);
}

TEST(TimelapseFarm, AServerKilledMidWayIsReplacedAndTheTimelapseFinishes) {
  const fs::path dir = fresh_dir("restart");
  std::string id;
  nlohmann::json before;
  {
    FarmServer server(dir / "data", 1);
    ASSERT_TRUE(server.ok()) << server.log();
    id = submit_id(server, slow_timelapse(256));
    ASSERT_FALSE(id.empty());
    for (int i = 0; i < 1500; ++i) {
      before = get(server, "/v1/timelapses/" + id).json();
      if (before.is_object() && before["progress"]["fraction"].get<double>() > 0.05) break;
      std::this_thread::sleep_for(10ms);
    }
    ASSERT_EQ(before["state"], "running") << before.dump(1);
    EXPECT_GT(before["progress"]["fraction"].get<double>(), 0.05);
    server.kill_now();  // SIGKILL, mid-way
  }
  FarmServer restarted(dir / "data", 2);
  ASSERT_TRUE(restarted.ok()) << restarted.log();
  const Answer shown = get(restarted, "/v1/timelapses/" + id);
  ASSERT_EQ(shown.status, 200);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(shown.json()["frames"][i]["render_id"], before["frames"][i]["render_id"]);
  const auto s = wait_timelapse(restarted, id, 150s);
  ASSERT_EQ(s["state"], "done") << s.dump(1) << restarted.log();
  EXPECT_EQ(get(restarted, "/v1/timelapses/" + id + "/contact_sheet.png").status, 200);
}

TEST(TimelapseFarm, CancelStopsEveryFrame) {
  const fs::path dir = fresh_dir("cancel");
  FarmServer server(dir / "data", 2);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string id = submit_id(server, slow_timelapse(65536));
  ASSERT_FALSE(id.empty());
  for (int i = 0; i < 300 && get(server, "/v1/timelapses/" + id).json()["state"] != "running"; ++i)
    std::this_thread::sleep_for(10ms);
  auto c = server.client();
  const auto res = c.Delete(("/v1/timelapses/" + id).c_str());
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 202);
  const auto s = nlohmann::json::parse(res->body);
  EXPECT_EQ(s["state"], "cancelled");
  for (const auto& f : s["frames"]) {
    EXPECT_EQ(f["state"], "cancelled");
    EXPECT_EQ(server.status(f["render_id"])["state"], "cancelled");
  }
  EXPECT_EQ(get(server, "/v1/timelapses/" + id + "/contact_sheet.png").status, 409);
  // The workers are free again: a small render finishes.
  const std::string small = server.submit(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 0},
      "camera": {"projection": "equirectangular", "width": 16, "height": 8}, "method": "lut"})");
  EXPECT_EQ(server.wait(small, 60s)["state"], "done");
}

TEST(TimelapseFarm, BadRequestsNameTheFieldAndFilesWaitForTheirTurn) {
  const fs::path dir = fresh_dir("bad");
  FarmServer server(dir / "data", 0);  // no workers: nothing finishes
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string range = R"("start": "2013-05-27T17:00:00Z", "end": "2013-05-27T18:00:00Z")";
  const std::string camera = R"("camera": {"projection": "fisheye", "width": 16, "height": 16})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{" + camera + ", " + range + "}", "step_s"},
      {"{" + camera + ", " + range + R"(, "frames": 5000})", "frames"},
      {"{" + camera + ", " + range + R"(, "step_s": 0.5})", "step_s"},
      {"{" + camera + R"(, "start": "yesterday", "end": "2013-05-27T18:00:00Z", "frames": 3})", "start"},
      {"{" + camera + ", " + range + R"(, "frames": 3, "time": "2013-05-27T17:00:00Z"})", "time"},
      {"{" + camera + ", " + range + R"(, "frames": 3, "same_seed": "yes"})", "same_seed"},
      {"{" + range + R"(, "frames": 3, "camera": {"projection": "fisheye", "width": 0}})", "camera.width"},
  };
  for (const auto& [body, field] : cases) {
    const Answer a = post(server, "/v1/timelapses", body);
    EXPECT_EQ(a.status, 400) << body;
    EXPECT_EQ(a.content_type, "application/problem+json");
    const auto errors = a.json()["errors"];
    ASSERT_TRUE(errors.is_array() && !errors.empty()) << a.body;
    EXPECT_EQ(errors[0]["field"], field) << a.body;
  }
  EXPECT_EQ(get(server, "/v1/timelapses").json()["total"], 0) << "bad requests change nothing";
  EXPECT_EQ(get(server, "/v1/renders").json()["total"], 0);

  const std::string id = submit_id(server, "{" + camera + ", " + range + R"(, "frames": 3, "method": "lut"})");
  ASSERT_FALSE(id.empty());
  const std::string base = "/v1/timelapses/" + id;
  EXPECT_EQ(get(server, base).json()["state"], "queued");
  for (const char* file : {"/contact_sheet.png", "/video.mp4", "/frames/0.png", "/frames/2.exr"}) {
    const Answer a = get(server, base + file);
    EXPECT_EQ(a.status, 409) << file << ": " << a.body;
    EXPECT_EQ(a.content_type, "application/problem+json") << file;
  }
  EXPECT_EQ(get(server, base + "/frames/3.png").status, 404);
  EXPECT_EQ(get(server, base + "/frames/x.png").json()["errors"][0]["field"], "frame");
  EXPECT_EQ(get(server, "/v1/timelapses/0123456789abcdef").status, 404);
  EXPECT_EQ(get(server, "/v1/timelapses/0123456789abcdef/contact_sheet.png").status, 404);
  auto c = server.client();
  const auto put = c.Put(base.c_str(), "{}", "application/json");
  ASSERT_TRUE(put);
  EXPECT_EQ(put->status, 405);
  EXPECT_EQ(put->get_header_value("Allow"), "GET, HEAD, DELETE");
  // The OpenAPI document the server serves names every timelapse route.
  const Answer openapi = get(server, "/v1/openapi.yaml");
  for (const char* route : {"/v1/timelapses:", "/v1/timelapses/{id}:", "/v1/timelapses/{id}/frames:",
                            "/v1/timelapses/{id}/frames/{n}.exr:", "/v1/timelapses/{id}/frames/{n}.png:",
                            "/v1/timelapses/{id}/contact_sheet.png:", "/v1/timelapses/{id}/video.mp4:"})
    EXPECT_NE(openapi.body.find(route), std::string::npos) << route;
  EXPECT_EQ(get(server, "/healthz").status, 200);
}

}  // namespace
}  // namespace skyfarm
