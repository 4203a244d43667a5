// Cloud volume uploads on a real httplib::Server: an OpenVDB file written
// here with the OpenVDB API becomes a SKYVOL1 asset named by its hash;
// malformed files, missing grids and transforms the renderer cannot place
// are 4xx, and the server (whose importer runs in a child process) keeps
// answering.
#include <gtest/gtest.h>
#include <httplib.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include "common/assets/volume_file.h"
#include "server/assets/asset_admission.h"
#include "server/assets/asset_http.h"
#include "server/assets/asset_store.h"
#include "tests/support/http_fixture.h"
#include "tests/support/mesh_files.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace skyfarm::testing;

// A 6 x 5 x 4 blob of density in 20 m voxels, as a .vdb stream.
std::string blob_vdb(const std::string& name = "density", bool rotated = false) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  auto transform = openvdb::math::Transform::createLinearTransform(20.0);
  if (rotated) transform->postRotate(0.5, openvdb::math::Y_AXIS);
  grid->setTransform(transform);
  auto acc = grid->getAccessor();
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 6; ++x) acc.setValue(openvdb::Coord(x, y, z), 0.1f * float(1 + x + y + z));
  std::ostringstream out(std::ios::binary);
  openvdb::io::Stream(out).write({grid});
  return out.str();
}

class VolumeUploadTest : public testing::HttpFixture {
 protected:
  void SetUp() override {
    fs::remove_all(dir_);
    AssetStoreOptions options;
    options.max_upload_bytes = 1 << 20;
    options.import.command = {SKYFARM_SERVER_BINARY, "import-mesh"};
    options.volume_import.command = {SKYFARM_SERVER_BINARY, "import-volume"};
    options.volume_import.timeout = 10s;
    options.volume_import.cpu_seconds = 5;
    options.volume_import.memory_bytes = std::uint64_t{2} << 30;
    options.volume_import.limits.max_voxels = 100000;
    store_ = std::make_unique<AssetStore>(dir_.string(), options);
    HttpOptions http;
    http.assets = store_.get();
    serve(std::move(http));
  }
  void TearDown() override {
    HttpFixture::TearDown();
    store_.reset();
    fs::remove_all(dir_);
  }
  httplib::Result upload(const std::string& bytes, const std::string& query = "",
                         const std::string& type = "application/octet-stream") {
    auto c = client();
    c.set_read_timeout(30);
    return c.Post(("/v1/assets" + query).c_str(), bytes, type.c_str());
  }

  const fs::path dir_ = fs::temp_directory_path() / ("skyfarm_volumes_" + std::to_string(::getpid()));
  std::unique_ptr<AssetStore> store_;
};

nlohmann::json json_of(const httplib::Result& r) { return nlohmann::json::parse(r->body); }

void expect_problem(const httplib::Result& r, int status, const std::string& detail_part = "") {
  ASSERT_TRUE(r) << "no response";
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  if (!detail_part.empty()) {
    EXPECT_NE(json_of(r).value("detail", "").find(detail_part), std::string::npos) << r->body;
  }
}

TEST_F(VolumeUploadTest, UploadGetAndReupload) {
  const std::string vdb = blob_vdb();
  const auto first = upload(vdb);  // detected by its magic
  ASSERT_TRUE(first);
  ASSERT_EQ(first->status, 201) << first->body;
  const nlohmann::json meta = json_of(first);
  const std::string id = meta.at("id");
  EXPECT_TRUE(is_asset_id(id)) << id;
  EXPECT_EQ(meta.at("kind"), "volume");
  EXPECT_EQ(meta.at("voxels"), nlohmann::json::array({6, 5, 4}));
  EXPECT_EQ(meta.at("voxel_size_m"), nlohmann::json::array({20.0, 20.0, 20.0}));
  EXPECT_EQ(meta.at("bounds").at("max"), nlohmann::json::array({100.0, 80.0, 60.0}));
  EXPECT_EQ(first->get_header_value("Location"), "/v1/assets/" + id);

  // Again, by format and by content type: the same asset.
  for (const auto& [query, type] : std::vector<std::pair<std::string, std::string>>{
           {"?format=vdb", "application/octet-stream"}, {"?grid=density", "application/x-openvdb"}}) {
    const auto again = upload(vdb, query, type);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->status, 200) << again->body;
    EXPECT_EQ(json_of(again), meta);
  }

  auto c = client();
  const auto file = c.Get(("/v1/assets/" + id + "/volume").c_str());
  ASSERT_TRUE(file);
  ASSERT_EQ(file->status, 200);
  EXPECT_EQ("sha256:" + sha256_hex(file->body), id) << "the id is the hash of the SKYVOL1 file";
  assets::VolumeGrid g;
  std::string error;
  ASSERT_TRUE(assets::decode_volume_file(file->body, {}, &g, &error)) << error;
  EXPECT_EQ(g.size, glm::ivec3(6, 5, 4));
  EXPECT_FLOAT_EQ(g.at(5, 4, 3), 1.3f);
  // Workers fetch it by id like a mesh; its /mesh is not there.
  EXPECT_EQ(store_->asset_file(id), file->body);
  expect_problem(c.Get(("/v1/assets/" + id + "/mesh").c_str()), 404);

  // Admission: a request's clouds.volumes naming it pass, a mesh or an unknown id does not.
  CloudsSpec clouds;
  clouds.volumes.resize(1);
  clouds.volumes[0].asset = id;
  EXPECT_TRUE(missing_volume_assets(clouds, store_.get()).empty());
  ObjectSpec object;
  object.shape = ShapeKind::kMesh;
  object.asset = id;
  EXPECT_EQ(missing_assets({object}, store_.get()).size(), 1u) << "a volume is not a mesh";
  clouds.volumes[0].asset = "sha256:" + std::string(64, 'b');
  const auto errors = missing_volume_assets(clouds, store_.get());
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].path, "clouds.volumes[0].asset");
}

TEST_F(VolumeUploadTest, BadFilesAre4xxAndTheServerStaysUp) {
  const std::string vdb = blob_vdb();
  expect_problem(upload(vdb.substr(0, 4) + std::string(300, '\xee')), 422);
  expect_problem(upload(vdb.substr(0, vdb.size() / 2)), 422);
  expect_problem(upload("not a volume at all", "?format=vdb"), 422, "not an OpenVDB file");
  expect_problem(upload(blob_vdb("smoke"), "?grid=density"), 422, "no float grid named \"density\"");
  expect_problem(upload(blob_vdb("density", true)), 422, "rotates");
  expect_problem(upload(vdb, "?format=obj&grid=density"), 400);
  // Over the voxel limit (100000 here): 50^3 active voxels.
  {
    auto big = openvdb::FloatGrid::create(0.0f);
    big->setName("density");
    big->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(49)), 1.0f);
    std::ostringstream out(std::ios::binary);
    openvdb::io::Stream(out).write({big});
    expect_problem(upload(out.str()), 422, "more than the limit");
  }
  // Bit flips and truncations of a valid file: answered, never 5xx.
  std::mt19937_64 rng(7);
  for (int i = 0; i < 24; ++i) {
    std::string bytes = vdb;
    if (i % 2) {
      bytes.resize(4 + rng() % (bytes.size() - 4));
    } else {
      for (int n = 0; n < 8; ++n) bytes[4 + rng() % (bytes.size() - 4)] ^= char(1 << (rng() % 8));
    }
    const auto r = upload(bytes);
    ASSERT_TRUE(r) << "case " << i << ": no answer";
    EXPECT_LT(r->status, 500) << "case " << i << ": " << r->body;
  }
  EXPECT_EQ(upload(vdb)->status / 100, 2) << "the server still imports volumes";
  EXPECT_EQ(upload(cube_obj(), "?format=obj")->status / 100, 2) << "and meshes";
  EXPECT_TRUE(fs::is_empty(dir_ / "assets" / "tmp"));
}

}  // namespace
}  // namespace skyfarm::server
