// Mesh assets on the farm, end to end on loopback: a mesh uploaded once
// renders on worker processes that share no files with the server and start
// with empty caches; the image is byte-identical to `skyfarm-worker render`
// of the same request naming the mesh file; each worker fetches the asset at
// most once; a worker killed mid-job costs nothing; a request naming an
// asset the server lacks is refused before it becomes a job, and so is a
// cloud volume's (clouds.volumes[i].asset), while cloud layers, which name
// no asset, are admitted and counted in the plan.
#include <gtest/gtest.h>

#include <regex>

#include "common/assets/asset_id.h"
#include "tests/farm/farm_process.h"
#include "tests/support/mesh_files.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

fs::path fresh_dir(const std::string& name) { return testing::fresh_dir("skyfarm_farm_assets", name); }

// A tetrahedron 2 m north of the camera, a grey sphere beside it, under a
// low sun, small enough to render in seconds.
std::string request_with(const std::string& asset) {
  return R"({
    "sun": {"zenith_deg": 70, "azimuth_deg": 150},
    "location": {"altitude_m": 1.5},
    "camera": {"projection": "perspective", "width": 48, "height": 32, "fov_deg": 70, "pitch_deg": -15},
    "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 16},
    "output": {"half": false},
    "objects": [
      {"name": "tetra", "shape": "mesh", "asset": ")" +
         asset + R"(", "albedo": 0.6, "translate_m": [-0.5, 3, 0], "scale": 1},
      {"name": "ball", "shape": "sphere", "material": {"name": "chrome", "roughness": 0.1},
       "translate_m": [1, 3, 0.4], "scale": 0.4}
    ],
    "seed": 3
  })";
}

// Uploads the mesh; its id, or "" on failure.
std::string upload(const FarmServer& server, const std::string& bytes) {
  auto client = server.client();
  const auto res = client.Post("/v1/assets?format=obj", bytes, "application/octet-stream");
  if (!res || (res->status != 201 && res->status != 200)) return "";
  return nlohmann::json::parse(res->body)["id"].get<std::string>();
}

// The value of a counter in /metrics (-1 when absent).
long long metric(const FarmServer& server, const std::string& name) {
  auto client = server.client();
  const auto res = client.Get("/metrics");
  if (!res) return -1;
  std::smatch m;
  if (!std::regex_search(res->body, m, std::regex("\n" + name + " (\\d+)\n"))) return -1;
  return std::stoll(m[1]);
}

// How many times the worker's log says it asked the server for an asset.
int fetches_in(const fs::path& log) {
  const std::string text = testing::read_text(log);
  int n = 0;
  for (std::size_t at = 0; (at = text.find("fetching asset", at)) != std::string::npos; ++at) ++n;
  return n;
}

pid_t start_worker(const FarmServer& server, const fs::path& log, const fs::path& cache) {
  return testing::spawn_process({SKYFARM_WORKER_BINARY, "--connect", server.endpoint(), "--threads", "1",
                                 "--secret-file", server.secret_file().string(), "--asset-cache", cache.string()},
                                log);
}

// The local render of the request naming the OBJ file by path.
std::string local_exr(const fs::path& dir) {
  std::ofstream(dir / "tetra.obj") << testing::tetra_obj();
  return testing::local_render_exr(request_with("tetra.obj"), dir);
}

TEST(FarmAssets, AnUploadedMeshRendersWithTheLocalBytesAndIsFetchedOncePerWorker) {
  const fs::path dir = fresh_dir("render");
  const std::string local = local_exr(fresh_dir("render_local"));
  ASSERT_FALSE(local.empty()) << "skyfarm-worker render of the mesh file failed";
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string id = upload(server, testing::tetra_obj());
  ASSERT_TRUE(assets::is_asset_id(id)) << id;
  const pid_t a = start_worker(server, dir / "a.log", dir / "cache-a");
  const pid_t b = start_worker(server, dir / "b.log", dir / "cache-b");
  const std::string job = server.submit(request_with(id));
  ASSERT_FALSE(job.empty());
  const auto status = server.wait(job, std::chrono::seconds(120));
  testing::kill_and_wait(a, SIGTERM);
  testing::kill_and_wait(b, SIGTERM);
  ASSERT_EQ(status["state"], "done") << status.dump() << testing::read_text(dir / "a.log");
  EXPECT_EQ(server.download(job, "image.exr"), local);
  EXPECT_LE(fetches_in(dir / "a.log"), 1) << testing::read_text(dir / "a.log");
  EXPECT_LE(fetches_in(dir / "b.log"), 1) << testing::read_text(dir / "b.log");
  const long long served = metric(server, "skyfarm_assets_served_total");
  EXPECT_GE(served, 1);
  EXPECT_LE(served, 2) << "at most once per worker";
  EXPECT_EQ(metric(server, "skyfarm_assets_refused_total"), 0);
  EXPECT_TRUE(fs::exists(dir / "cache-a" / (std::string(assets::asset_hex(id)) + ".mesh")) ||
              fs::exists(dir / "cache-b" / (std::string(assets::asset_hex(id)) + ".mesh")))
      << "the fetched file is kept";
}

TEST(FarmAssets, AWorkerKilledMidJobCostsNothing) {
  const fs::path dir = fresh_dir("kill");
  const std::string local = local_exr(fresh_dir("kill_local"));
  ASSERT_FALSE(local.empty());
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string id = upload(server, testing::tetra_obj());
  ASSERT_TRUE(assets::is_asset_id(id)) << id;
  const pid_t a = start_worker(server, dir / "a.log", dir / "cache-a");
  const pid_t b = start_worker(server, dir / "b.log", dir / "cache-b");
  const std::string job = server.submit(request_with(id));
  ASSERT_FALSE(job.empty());
  for (int i = 0; i < 400 && server.status(job)["progress"]["units_done"].get<int>() < 2; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  testing::kill_and_wait(a, SIGKILL);
  const auto status = server.wait(job, std::chrono::seconds(120));
  testing::kill_and_wait(b, SIGTERM);
  ASSERT_EQ(status["state"], "done") << status.dump();
  EXPECT_EQ(server.download(job, "image.exr"), local);
}

TEST(FarmAssets, AnAssetTheServerLacksIsRefusedBeforeAJobIsMade) {
  const fs::path dir = fresh_dir("unknown");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  auto client = server.client();
  const std::string unknown = "sha256:" + std::string(64, '9');
  const auto res = client.Post("/v1/renders", request_with(unknown), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400) << res->body;
  EXPECT_NE(res->body.find("objects[0].asset"), std::string::npos) << res->body;
  const auto list = client.Get("/v1/renders");
  ASSERT_TRUE(list);
  EXPECT_EQ(nlohmann::json::parse(list->body)["total"], 0) << "no job was made";
}

TEST(FarmAssets, ACloudVolumeTheServerLacksIsRefusedButLayersAreAdmitted) {
  const fs::path dir = fresh_dir("clouds");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  auto client = server.client();
  const std::string sky = R"({"sun": {"zenith_deg": 40, "azimuth_deg": 200}, "camera": {"projection": "fisheye",
      "width": 16, "height": 16}, "clouds": )";
  const std::string unknown = "sha256:" + std::string(64, '9');
  const auto refused = client.Post(
      "/v1/renders", sky + R"({"layers": [{"type": "cumulus"}], "volumes": [{"asset": ")" + unknown + R"("}]}})",
      "application/json");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 400) << refused->body;
  EXPECT_NE(refused->body.find("clouds.volumes[0].asset"), std::string::npos) << refused->body;
  const auto list = client.Get("/v1/renders");
  ASSERT_TRUE(list);
  EXPECT_EQ(nlohmann::json::parse(list->body)["total"], 0) << "no job was made";

  const auto admitted =
      client.Post("/v1/renders", sky + R"({"layers": [{"type": "stratus"}, {"type": "cirrus"}]}})", "application/json");
  ASSERT_TRUE(admitted);
  ASSERT_EQ(admitted->status, 202) << admitted->body;
  const nlohmann::json status = server.status(nlohmann::json::parse(admitted->body)["id"].get<std::string>());
  EXPECT_EQ(status["plan"]["clouds"],
            nlohmann::json::parse(R"({"layers": 2, "layer_types": ["stratus", "cirrus"], "volumes": 0})"))
      << status.dump();
}

}  // namespace
}  // namespace skyfarm
