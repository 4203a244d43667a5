// Admission of mesh objects (server/assets/asset_admission.h): an asset the
// store lacks is a field error naming objects[i].asset; other shapes pass.
#include "server/assets/asset_admission.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/assets/asset_id.h"
#include "server/assets/asset_store.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

ObjectSpec object(ShapeKind shape, std::string asset = "") {
  ObjectSpec o;
  o.shape = shape;
  o.asset = std::move(asset);
  return o;
}

TEST(AssetAdmission, MeshesMustBeInTheStore) {
  const fs::path dir = fs::temp_directory_path() / ("skyfarm_admission_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  AssetStore store(dir.string(), {});
  // A stored asset as the store lays it out: the mesh, then its metadata.
  const std::string hex = assets::sha256_hex("mesh");
  const std::string stored = "sha256:" + hex;
  std::ofstream(dir / "assets" / (hex + ".mesh")) << "mesh";
  std::ofstream(dir / "assets" / (hex + ".json")) << R"({"id": ")" << stored << R"("})";
  ASSERT_TRUE(store.meta(stored));
  const std::string absent = "sha256:" + std::string(64, '7');

  EXPECT_TRUE(missing_assets({}, &store).empty());
  EXPECT_TRUE(missing_assets({object(ShapeKind::kSphere), object(ShapeKind::kMesh, stored)}, &store).empty());
  const auto errors =
      missing_assets({object(ShapeKind::kBox), object(ShapeKind::kMesh, absent), object(ShapeKind::kMesh, stored)}, &store);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].path, "objects[1].asset");
  EXPECT_NE(errors[0].rule.find("upload"), std::string::npos) << errors[0].rule;
  EXPECT_NE(errors[0].message().find(absent), std::string::npos) << errors[0].message();

  const auto no_store = missing_assets({object(ShapeKind::kMesh, stored), object(ShapeKind::kDisc)}, nullptr);
  ASSERT_EQ(no_store.size(), 1u);
  EXPECT_EQ(no_store[0].path, "objects[0].asset");
  fs::remove_all(dir);
}

// Cloud volumes name their grids by asset id as meshes do: the same rule,
// the field clouds.volumes[i].asset.
TEST(AssetAdmission, CloudVolumesMustBeInTheStore) {
  const fs::path dir = fs::temp_directory_path() / ("skyfarm_admission_clouds_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  AssetStore store(dir.string(), {});
  const std::string hex = assets::sha256_hex("volume");
  const std::string stored = "sha256:" + hex;
  std::ofstream(dir / "assets" / (hex + ".mesh")) << "volume";
  std::ofstream(dir / "assets" / (hex + ".json")) << R"({"id": ")" << stored << R"("})";
  ASSERT_TRUE(store.meta(stored));
  const std::string absent = "sha256:" + std::string(64, '7');

  CloudsSpec clouds;
  clouds.layers.resize(3);  // layers name no assets
  EXPECT_TRUE(missing_volume_assets(clouds, &store).empty());
  EXPECT_TRUE(missing_volume_assets(clouds, nullptr).empty());
  clouds.volumes.resize(2);
  clouds.volumes[0].asset = stored;
  clouds.volumes[1].asset = absent;
  const auto errors = missing_volume_assets(clouds, &store);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].path, "clouds.volumes[1].asset");
  EXPECT_NE(errors[0].rule.find("upload"), std::string::npos) << errors[0].rule;
  EXPECT_NE(errors[0].message().find(absent), std::string::npos) << errors[0].message();
  EXPECT_EQ(missing_volume_assets(clouds, nullptr).size(), 2u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skyfarm::server
