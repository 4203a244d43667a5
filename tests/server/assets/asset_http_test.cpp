// The mesh asset routes on a real httplib::Server: upload, idempotent
// re-upload, metadata, the mesh file, 400/404/413/422, and a fuzz run of
// malformed files that must leave the server alive and answering 4xx.
#include "server/assets/asset_http.h"

#include <gtest/gtest.h>
#include <httplib.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "common/assets/mesh_file.h"
#include "common/assets/mesh_import.h"
#include "server/assets/asset_store.h"
#include "tests/support/http_fixture.h"
#include "tests/support/mesh_files.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace skyfarm::testing;

class AssetHttpTest : public testing::HttpFixture {
 protected:
  void SetUp() override {
    fs::remove_all(dir_);
    AssetStoreOptions options;
    options.max_upload_bytes = 64 * 1024;
    options.import.command = {SKYFARM_SERVER_BINARY, "import-mesh"};
    options.import.timeout = 3s;
    options.import.cpu_seconds = 1;
    options.import.memory_bytes = std::uint64_t{1} << 30;
    options.import.limits.max_triangles = 10000;
    options.import.limits.max_vertices = 30000;
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
  httplib::Result upload(const std::string& bytes, const std::string& query = "") {
    auto c = client();
    c.set_read_timeout(30);
    return c.Post(("/v1/assets" + query).c_str(), bytes, "application/octet-stream");
  }

  const fs::path dir_ = fs::temp_directory_path() / ("skyfarm_assets_" + std::to_string(::getpid()));
  std::unique_ptr<AssetStore> store_;
};

nlohmann::json json_of(const httplib::Result& r) { return nlohmann::json::parse(r->body); }

void expect_problem(const httplib::Result& r, int status) {
  ASSERT_TRUE(r) << "no response";
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  EXPECT_EQ(json_of(r).at("status"), status);
}

TEST_F(AssetHttpTest, UploadReuploadAndGet) {
  const auto first = upload(cube_obj(), "?format=obj");
  ASSERT_TRUE(first);
  ASSERT_EQ(first->status, 201) << first->body;
  const nlohmann::json meta = json_of(first);
  const std::string id = meta.at("id");
  EXPECT_TRUE(is_asset_id(id)) << id;
  EXPECT_EQ(meta.at("triangles"), 12);
  EXPECT_EQ(meta.at("vertices"), 8);
  EXPECT_EQ(meta.at("bounds").at("min"), nlohmann::json::array({0, 0, 0}));
  EXPECT_EQ(meta.at("bounds").at("max"), nlohmann::json::array({1, 1, 1}));
  EXPECT_EQ(first->get_header_value("Location"), "/v1/assets/" + id);

  // The same bytes again, and the same cube with the format detected: one asset.
  for (const std::string query : {"?format=obj", ""}) {
    const auto again = upload(cube_obj(), query);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->status, 200) << again->body;
    EXPECT_EQ(json_of(again), meta);
  }

  auto c = client();
  const auto got = c.Get(("/v1/assets/" + id).c_str());
  ASSERT_TRUE(got);
  EXPECT_EQ(got->status, 200);
  EXPECT_EQ(json_of(got), meta);

  const auto mesh = c.Get(("/v1/assets/" + id + "/mesh").c_str());
  ASSERT_TRUE(mesh);
  ASSERT_EQ(mesh->status, 200);
  EXPECT_EQ(mesh->get_header_value("Content-Type"), "application/octet-stream");
  EXPECT_EQ("sha256:" + sha256_hex(mesh->body), id) << "the id is the hash of the mesh file";
  assets::TriangleMesh m;
  std::string error;
  ASSERT_TRUE(assets::decode_mesh_file(mesh->body, {}, &m, &error)) << error;
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_TRUE(fs::exists(dir_ / "assets" / (id.substr(7) + ".mesh")));
}

TEST_F(AssetHttpTest, EveryFormatUploads) {
  for (const auto& [format, bytes] : std::vector<std::pair<std::string, std::string>>{
           {"obj", tetra_obj()}, {"ply", tetra_ply_binary()}, {"stl", tetra_stl_binary()},
           {"stl", tetra_stl_ascii()}, {"gltf", tetra_gltf()}, {"glb", tetra_glb()}}) {
    const auto r = upload(bytes, "?format=" + format);
    ASSERT_TRUE(r) << format;
    EXPECT_TRUE(r->status == 201 || r->status == 200) << format << ": " << r->body;
    EXPECT_EQ(json_of(r).at("triangles"), 4) << format;
  }
}

TEST_F(AssetHttpTest, Errors) {
  auto c = client();
  const std::string unknown = "sha256:" + std::string(64, 'a');
  expect_problem(c.Get(("/v1/assets/" + unknown).c_str()), 404);
  expect_problem(c.Get(("/v1/assets/" + unknown + "/mesh").c_str()), 404);
  expect_problem(c.Get("/v1/assets/sha256:ABC"), 400);
  expect_problem(c.Get("/v1/assets/../etc/passwd"), 404);
  expect_problem(upload(cube_obj(), "?format=fbx"), 400);
  expect_problem(upload(""), 422);
  expect_problem(upload("\x01\x02 not a mesh"), 422);
  expect_problem(upload("v 0 0 0\nf 1 2 3\n", "?format=obj"), 422);
  const auto too_large = upload(std::string(64 * 1024 + 1, 'v'), "?format=obj");
  expect_problem(too_large, 413);
  const auto wrong_method = c.Delete("/v1/assets");
  expect_problem(wrong_method, 405);
  EXPECT_EQ(json_of(upload(cube_obj(), "?format=obj")).at("triangles"), 12) << "the server still works";
}

// Malformed files: the valid ones truncated, bit-flipped, with huge counts
// in their headers, and random bytes.  Each is uploaded (format given, or
// detected every third time); the server must answer every one, never with a
// 5xx, and the files that are not meshes at all with a 4xx.
TEST_F(AssetHttpTest, FuzzedUploadsNeverTakeTheServerDown) {
  const std::vector<std::pair<std::string, std::string>> seeds = {
      {"obj", cube_obj()},          {"ply", tetra_ply_ascii()}, {"ply", tetra_ply_binary()},
      {"stl", tetra_stl_binary()},  {"stl", tetra_stl_ascii()}, {"gltf", tetra_gltf()},
      {"glb", tetra_glb()}};
  // Headers that claim far more than the file holds.
  std::vector<std::pair<std::string, std::string>> huge = {
      {"ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nproperty float x\n"
              "property float y\nproperty float z\nelement face 4294967295\n"
              "property list uchar int vertex_indices\nend_header\n" + std::string(64, '\xff')},
      {"ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uint int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
              "4000000000 0 1 2\n"},
      {"obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4000000000\nf -1 -2 -99999999\n"},
      {"obj", "v 1e400 0 0\nv nan 0 0\nv 0 inf 0\nf 1 2 3\n"},
      {"gltf", tetra_gltf_json("data:application/octet-stream;base64,AAAA")},
      {"gltf", R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
               R"("accessors":[{"componentType":5126,"count":4294967295,"type":"VEC3"}]})"}};
  {
    std::string stl = tetra_stl_binary();
    const std::uint32_t big = 0xFFFFFFFFu;
    std::memcpy(stl.data() + 80, &big, 4);
    huge.emplace_back("stl", stl);
    std::string glb = tetra_glb();
    std::memcpy(glb.data() + 8, &big, 4);
    huge.emplace_back("glb", glb);
    std::string glb_chunk = tetra_glb();
    std::memcpy(glb_chunk.data() + 12, &big, 4);
    huge.emplace_back("glb", glb_chunk);
  }

  std::mt19937_64 rng(20261203);
  auto uniform = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
  constexpr int kCases = 1000;
  int answered = 0, refused = 0, accepted = 0;
  for (int i = 0; i < kCases; ++i) {
    std::string format, bytes;
    bool must_refuse = false;
    switch (i % 4) {
      case 0: {  // truncated
        std::tie(format, bytes) = seeds[uniform(seeds.size())];
        bytes.resize(uniform(bytes.size()));
        break;
      }
      case 1: {  // bit flips
        std::tie(format, bytes) = seeds[uniform(seeds.size())];
        for (std::size_t n = 1 + uniform(16); n > 0; --n) bytes[uniform(bytes.size())] ^= char(1 << uniform(8));
        break;
      }
      case 2: {  // random bytes, a known magic in front sometimes
        format = std::string(assets::kMeshFormats[uniform(5)]);
        bytes.resize(uniform(2048));
        for (char& b : bytes) b = static_cast<char>(rng());
        if (uniform(2)) bytes = std::string(format == "glb" ? "glTF" : format == "ply" ? "ply\n" : "solid ") + bytes;
        must_refuse = true;
        break;
      }
      case 3: {  // huge counts, and those bit-flipped
        std::tie(format, bytes) = huge[uniform(huge.size())];
        if (i % 8 == 7) bytes[uniform(bytes.size())] ^= char(1 << uniform(8));
        must_refuse = i % 8 == 3;
        break;
      }
    }
    const auto start = std::chrono::steady_clock::now();
    const auto r = upload(bytes, i % 3 == 0 ? "" : "?format=" + format);
    if (std::chrono::steady_clock::now() - start > 500ms)
      std::cout << "[ slow     ] case " << i << " (" << format << ", kind " << i % 4 << "): "
                << (r ? r->body.substr(0, 200) : std::string("no answer")) << "\n";
    ASSERT_TRUE(r) << "case " << i << ": no answer (" << httplib::to_string(r.error()) << ")";
    ++answered;
    ASSERT_LT(r->status, 500) << "case " << i << " (" << format << "): " << r->body;
    if (r->status >= 400) {
      ++refused;
      EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json") << "case " << i;
    } else {
      ++accepted;
      EXPECT_FALSE(must_refuse) << "case " << i << " (" << format << ") accepted: " << r->body;
    }
  }
  EXPECT_EQ(answered, kCases);
  EXPECT_GT(refused, kCases / 2);
  std::cout << "[ fuzz     ] " << kCases << " uploads: " << refused << " refused (4xx), " << accepted
            << " still a valid mesh (2xx)\n";
  // Still serving, and nothing left behind in the scratch directory.
  EXPECT_EQ(upload(cube_obj(), "?format=obj")->status / 100, 2);
  EXPECT_TRUE(fs::is_empty(dir_ / "assets" / "tmp"));
}

}  // namespace
}  // namespace skyfarm::server
