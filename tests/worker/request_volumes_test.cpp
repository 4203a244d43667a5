// `skyfarm-worker render`'s cloud volume files (worker/request_assets.h): a
// .vdb or SKYVOL1 path becomes the id the farm's upload would give, the
// volume is served under it, and errors name their field.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include "api/field_error.h"
#include "common/assets/asset_id.h"
#include "common/assets/vdb_import.h"
#include "common/assets/volume_file.h"
#include "worker/request_assets.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

std::string cube_vdb(const std::string& name) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(50.0));
  grid->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(3)), 0.75f);
  std::ostringstream out(std::ios::binary);
  openvdb::io::Stream(out).write({grid});
  return out.str();
}

TEST(RequestVolumes, PathsBecomeTheFarmsIdsAndAreServed) {
  const fs::path dir = fs::temp_directory_path() / ("skyfarm_reqvolumes_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "cache");
  const std::string vdb = cube_vdb("smoke");
  std::ofstream(dir / "cloud.vdb", std::ios::binary) << vdb;
  // The id the server's import would answer (the same importer, then the hash of SKYVOL1).
  assets::VolumeGrid grid;
  std::string error;
  ASSERT_TRUE(assets::import_vdb(vdb, "smoke", {}, &grid, &error)) << error;
  const std::string file = assets::encode_volume_file(grid);
  const std::string id = assets::asset_id_of(file);
  std::ofstream(dir / "cloud.skyvol", std::ios::binary) << file;

  nlohmann::json request = {
      {"clouds",
       {{"volumes",
         {{{"asset", "cloud.vdb"}, {"grid", "smoke"}}, {{"asset", (dir / "cloud.skyvol").string()}}}}}}};
  AssetDiskCache disk((dir / "cache").string(), 1 << 20);
  const auto source = resolve_request_volumes(&request, dir.string(), &disk);
  EXPECT_EQ(request["clouds"]["volumes"][0]["asset"], id);
  EXPECT_EQ(request["clouds"]["volumes"][1]["asset"], id);
  const auto served = source->volume(id);
  ASSERT_TRUE(served);
  EXPECT_EQ(served->size, glm::ivec3(4));
  EXPECT_EQ(served->at(3, 3, 3), 0.75f);

  nlohmann::json bad = {{"clouds",
                         {{"volumes",
                           {{{"asset", "cloud.vdb"}, {"grid", "density"}},
                            {{"asset", "missing.vdb"}},
                            {{"asset", "sha256:" + std::string(64, 'c')}}}}}}};
  try {
    (void)resolve_request_volumes(&bad, dir.string(), &disk);
    ADD_FAILURE() << "no error";
  } catch (const api::ValidationError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("clouds.volumes[0].asset"), std::string::npos) << what;
    EXPECT_NE(what.find("no float grid named \"density\""), std::string::npos) << what;
    EXPECT_NE(what.find("clouds.volumes[1].asset"), std::string::npos) << what;
    EXPECT_NE(what.find("no such file"), std::string::npos) << what;
    EXPECT_NE(what.find("clouds.volumes[2].asset"), std::string::npos) << what;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skyfarm
