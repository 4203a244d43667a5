// A cloud volume through the whole farm: the example .vdb uploaded to a real
// skyfarm-server (imported in its child process), a render naming it by id
// done by a real skyfarm-worker that fetches the SKYVOL1 file, and the image
// the same bits as `skyfarm-worker render` of the same request naming the
// .vdb file by path.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/assets/asset_id.h"
#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

const fs::path kCloud = fs::path(SKYFARM_SOURCE_DIR) / "api" / "examples" / "assets" / "cumulus.vdb";

// The cumulus 1.5 km north and 800 m up, filling the middle of a small view.
std::string request_with(const std::string& asset) {
  return R"({
    "sun": {"zenith_deg": 60, "azimuth_deg": 250},
    "camera": {"projection": "perspective", "width": 32, "height": 24, "fov_deg": 60, "pitch_deg": 25},
    "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 8},
    "output": {"half": false},
    "clouds": {"volumes": [{"asset": ")" +
         asset + R"(", "placement": {"translate_m": [0, 1500, 800]}, "density_scale": 0.05}]},
    "seed": 5
  })";
}

TEST(FarmVolume, AnUploadedVdbRendersAsTheLocalFileDoes) {
  const fs::path local_dir = testing::fresh_dir("skyfarm_farm_volume", "local");
  fs::copy_file(kCloud, local_dir / "cumulus.vdb");
  const std::string local = testing::local_render_exr(request_with("cumulus.vdb"), local_dir);
  ASSERT_FALSE(local.empty()) << "skyfarm-worker render of the .vdb file failed";

  const fs::path dir = testing::fresh_dir("skyfarm_farm_volume", "farm");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  auto client = server.client();
  const auto uploaded = client.Post("/v1/assets", testing::read_text(kCloud), "application/octet-stream");
  ASSERT_TRUE(uploaded);
  ASSERT_EQ(uploaded->status, 201) << uploaded->body;
  const std::string id = nlohmann::json::parse(uploaded->body)["id"];
  ASSERT_TRUE(assets::is_asset_id(id)) << id;

  const pid_t worker =
      testing::spawn_process({SKYFARM_WORKER_BINARY, "--connect", server.endpoint(), "--threads", "2",
                              "--secret-file", server.secret_file().string(), "--asset-cache",
                              (dir / "cache").string()},
                             dir / "worker.log");
  const std::string job = server.submit(request_with(id));
  ASSERT_FALSE(job.empty());
  const auto status = server.wait(job, std::chrono::seconds(120));
  testing::kill_and_wait(worker, SIGTERM);
  ASSERT_EQ(status["state"], "done") << status.dump() << testing::read_text(dir / "worker.log");
  EXPECT_EQ(server.download(job, "image.exr"), local) << "the farm's image is the local one, bit for bit";
}

}  // namespace
}  // namespace skyfarm
