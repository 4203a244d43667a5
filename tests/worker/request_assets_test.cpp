// `skyfarm-worker render`'s mesh files (worker/request_assets.h): a path
// becomes the id the farm would give the same mesh, an id is looked up in the
// worker's disk cache, and every error names its field.
#include "worker/request_assets.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "api/field_error.h"
#include "common/assets/asset_id.h"
#include "common/assets/mesh_file.h"
#include "common/assets/mesh_import.h"
#include "tests/support/mesh_files.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / ("skyfarm_reqassets_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name, std::ios::binary) << text;
  }
  fs::path path;
};

// The id POST /v1/assets answers for these bytes: the store imports with the
// same importer and hashes the canonical file.
std::string farm_id(const std::string& bytes, const std::string& format) {
  assets::TriangleMesh mesh;
  std::string error;
  EXPECT_TRUE(assets::import_mesh(bytes, format, {}, &mesh, &error)) << error;
  return assets::asset_id_of(assets::encode_mesh_file(mesh));
}

nlohmann::json request_with(const std::vector<std::string>& assets) {
  nlohmann::json objects = nlohmann::json::array();
  for (const auto& a : assets) objects.push_back({{"shape", "mesh"}, {"asset", a}, {"albedo", 0.5}});
  return {{"camera", {{"width", 8}}}, {"objects", objects}};
}

TEST(RequestAssets, AFilePathBecomesTheFarmsIdAndItsMeshIsServed) {
  TempDir dir("path");
  dir.write("tetra.obj", testing::tetra_obj());
  dir.write("cube.data", testing::cube_obj());  // no known extension: the bytes say OBJ
  fs::create_directories(dir.path / "meshes");
  dir.write("meshes/t.obj", testing::tetra_obj());
  TempDir cache("path_cache");
  AssetDiskCache disk(cache.path.string(), 1 << 20);
  nlohmann::json request = request_with({"tetra.obj", "cube.data", (dir.path / "meshes/t.obj").string()});
  request["objects"].push_back({{"shape", "sphere"}});
  const auto source = resolve_request_assets(&request, dir.path.string(), &disk);
  const std::string tetra = farm_id(testing::tetra_obj(), "obj");
  const std::string cube = farm_id(testing::cube_obj(), "obj");
  EXPECT_EQ(request["objects"][0]["asset"], tetra);
  EXPECT_EQ(request["objects"][1]["asset"], cube);
  EXPECT_EQ(request["objects"][2]["asset"], tetra) << "an absolute path, the same triangles";
  EXPECT_FALSE(request["objects"][3].contains("asset"));
  EXPECT_EQ(request["objects"][0]["albedo"], 0.5) << "the rest untouched";
  EXPECT_EQ(source->mesh(tetra)->triangle_count(), 4u);
  EXPECT_EQ(source->mesh(cube)->triangle_count(), 12u);
  EXPECT_TRUE(fs::is_empty(cache.path) || !fs::exists(cache.path)) << "a local render writes no cache";
}

TEST(RequestAssets, AnIdIsReadFromTheWorkersCache) {
  TempDir cache("id_cache");
  AssetDiskCache disk(cache.path.string(), 1 << 20);
  assets::TriangleMesh mesh;
  std::string error;
  ASSERT_TRUE(assets::import_mesh(testing::tetra_obj(), "obj", {}, &mesh, &error)) << error;
  const std::string file = assets::encode_mesh_file(mesh);
  const std::string id = assets::asset_id_of(file);
  disk.write(id, file);
  nlohmann::json request = request_with({id});
  const auto source = resolve_request_assets(&request, "/nonexistent", &disk);
  EXPECT_EQ(request["objects"][0]["asset"], id);
  EXPECT_EQ(source->mesh(id)->triangle_count(), 4u);
}

TEST(RequestAssets, ErrorsNameTheirFieldsAllAtOnce) {
  TempDir dir("errors");
  dir.write("notes.txt", "just some words\n");
  dir.write("broken.obj", "v 0 0 0\nf 1 2 3\n");
  TempDir cache("errors_cache");
  AssetDiskCache disk(cache.path.string(), 1 << 20);
  const std::string unknown = "sha256:" + std::string(64, 'f');
  nlohmann::json request = request_with({"missing.obj", "notes.txt", unknown, "broken.obj"});
  try {
    resolve_request_assets(&request, dir.path.string(), &disk);
    ADD_FAILURE() << "no error";
  } catch (const api::ValidationError& e) {
    ASSERT_EQ(e.errors().size(), 4u) << e.what();
    EXPECT_EQ(e.errors()[0].path, "objects[0].asset");
    EXPECT_NE(e.errors()[0].rule.find("cannot read missing.obj"), std::string::npos) << e.errors()[0].rule;
    EXPECT_EQ(e.errors()[1].path, "objects[1].asset");
    EXPECT_NE(e.errors()[1].rule.find("notes.txt"), std::string::npos) << e.errors()[1].rule;
    EXPECT_EQ(e.errors()[2].path, "objects[2].asset");
    EXPECT_NE(e.errors()[2].rule.find("upload it or give a file path"), std::string::npos) << e.errors()[2].rule;
    EXPECT_EQ(e.errors()[3].path, "objects[3].asset");
    EXPECT_NE(e.errors()[3].rule.find("cannot import broken.obj"), std::string::npos) << e.errors()[3].rule;
  }
}

TEST(RequestAssets, WhatIsNotTheirsIsLeftForTheParser) {
  AssetDiskCache disk("/nonexistent", 1);
  for (const char* text : {R"([1, 2])", R"({"objects": 3})", R"({"objects": [3, {"asset": 7}, {"asset": ""}]})"}) {
    nlohmann::json request = nlohmann::json::parse(text);
    const nlohmann::json before = request;
    EXPECT_NO_THROW(resolve_request_assets(&request, ".", &disk)) << text;
    EXPECT_EQ(request, before) << text;
  }
}

}  // namespace
}  // namespace skyfarm
