// OpenVDB import (common/assets/vdb_import.h): files written here with the
// OpenVDB API come back as the dense grid of their active box, in metres;
// transforms the renderer cannot place, missing grids, limits and garbage are
// refused with a sentence.
#include "common/assets/vdb_import.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

namespace skyfarm::assets {
namespace {

// A 4 x 3 x 2 block of active voxels at index (10..13, -5..-3, 7..8), value
// x + 10 y + 100 z of the offsets, one voxel inside left inactive (background 0).
openvdb::FloatGrid::Ptr block_grid(const std::string& name, double voxel_m, openvdb::Vec3d translate) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  auto transform = openvdb::math::Transform::createLinearTransform(voxel_m);
  transform->postTranslate(translate);
  grid->setTransform(transform);
  auto acc = grid->getAccessor();
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) acc.setValue(openvdb::Coord(10 + x, -5 + y, 7 + z), float(x + 10 * y + 100 * z));
  acc.setValueOff(openvdb::Coord(11, -4, 7), 0.0f);
  return grid;
}

std::string stream_bytes(const openvdb::GridPtrVec& grids) {
  std::ostringstream out(std::ios::binary);
  openvdb::io::Stream(out).write(grids);
  return out.str();
}

// What a user uploads: a file written by openvdb::io::File (Houdini, Blender).
std::string file_bytes(const openvdb::GridPtrVec& grids) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("skyfarm_vdb_import_test_" + std::to_string(::getpid()) + ".vdb");
  openvdb::io::File file(path.string());
  file.write(grids);
  file.close();
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  std::filesystem::remove(path);
  return s.str();
}

TEST(VdbImport, DenseActiveBoxInMetres) {
  openvdb::GridPtrVec grids{block_grid("density", 25.0, {100.0, 0.0, -50.0}), block_grid("other", 1.0, {})};
  for (const std::string& bytes : {stream_bytes(grids), file_bytes(grids)}) {
    ASSERT_TRUE(looks_like_vdb(bytes));
    VolumeGrid g;
    std::string error;
    ASSERT_TRUE(import_vdb(bytes, "density", {}, &g, &error)) << error;
    EXPECT_EQ(g.size, glm::ivec3(4, 3, 2));
    EXPECT_EQ(g.voxel_size_m, glm::dvec3(25.0));
    // Voxel (10, -5, 7)'s centre: index * 25 m + translation.
    EXPECT_EQ(g.origin_m, glm::dvec3(10 * 25.0 + 100.0, -5 * 25.0, 7 * 25.0 - 50.0));
    EXPECT_EQ(g.at(3, 2, 1), 3.0f + 20.0f + 100.0f);
    EXPECT_EQ(g.at(0, 0, 0), 0.0f);
    EXPECT_EQ(g.at(1, 1, 0), 0.0f);  // the inactive voxel: background
    EXPECT_EQ(g.at(2, 1, 0), 12.0f);
    EXPECT_EQ(g.max_value, 123.0f);
    // No name: "density".
    VolumeGrid unnamed;
    ASSERT_TRUE(import_vdb(bytes, "", {}, &unnamed, &error)) << error;
    EXPECT_EQ(unnamed.voxel_size_m, glm::dvec3(25.0));
  }
}

// The example asset, written by Debian's pyopenvdb (scripts/make-example-cloud.py):
// its active box and its transform (25 m voxels, centred in x and y).
TEST(VdbImport, TheExampleCloudReads) {
  std::ifstream in(std::filesystem::path(SKYFARM_SOURCE_DIR) / "api/examples/assets/cumulus.vdb", std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  VolumeGrid g;
  std::string error;
  ASSERT_TRUE(import_vdb(bytes.str(), "density", {}, &g, &error)) << error;
  EXPECT_EQ(g.voxel_size_m, glm::dvec3(25.0));
  EXPECT_EQ(g.size, glm::ivec3(32, 27, 24));  // index box (8, 10, 3)-(39, 36, 26) of 48 x 48 x 32
  EXPECT_EQ(g.origin_m, glm::dvec3(8 * 25.0 - 587.5, 10 * 25.0 - 587.5, 3 * 25.0));
  EXPECT_EQ(g.max_value, 1.0f);
}

TEST(VdbImport, ClampsValuesToFiniteNonNegative) {
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  auto acc = grid->getAccessor();
  acc.setValue(openvdb::Coord(0, 0, 0), -2.0f);
  acc.setValue(openvdb::Coord(1, 0, 0), std::numeric_limits<float>::quiet_NaN());
  acc.setValue(openvdb::Coord(2, 0, 0), std::numeric_limits<float>::infinity());
  acc.setValue(openvdb::Coord(3, 0, 0), 0.5f);
  VolumeGrid g;
  std::string error;
  ASSERT_TRUE(import_vdb(stream_bytes({grid}), "density", {}, &g, &error)) << error;
  ASSERT_EQ(g.size, glm::ivec3(4, 1, 1));
  EXPECT_EQ(g.values, (std::vector<float>{0.0f, 0.0f, 0.0f, 0.5f}));
  EXPECT_EQ(g.max_value, 0.5f);
}

std::string refusal(const std::string& bytes, std::string_view name, const VolumeLimits& limits = {}) {
  VolumeGrid g;
  std::string error;
  EXPECT_FALSE(import_vdb(bytes, name, limits, &g, &error));
  return error;
}

TEST(VdbImport, RefusesWhatItCannotPlace) {
  const std::string two = stream_bytes({block_grid("density", 1.0, {}), block_grid("temperature", 1.0, {})});
  EXPECT_NE(refusal(two, "smoke").find("no float grid named \"smoke\""), std::string::npos);
  const std::string other_two = stream_bytes({block_grid("smoke", 1.0, {}), block_grid("temperature", 1.0, {})});
  EXPECT_NE(refusal(other_two, "").find("2 float grids"), std::string::npos);

  auto rotated = block_grid("density", 1.0, {});
  rotated->transform().postRotate(0.3, openvdb::math::Z_AXIS);
  EXPECT_NE(refusal(stream_bytes({rotated}), "density").find("rotates"), std::string::npos);
  auto mirrored = block_grid("density", 1.0, {});
  mirrored->transform().postScale(openvdb::Vec3d(-1.0, 1.0, 1.0));
  EXPECT_NE(refusal(stream_bytes({mirrored}), "density").find("mirrors"), std::string::npos);
  auto frustum = block_grid("density", 1.0, {});
  frustum->setTransform(openvdb::math::Transform::createFrustumTransform(
      openvdb::BBoxd(openvdb::Vec3d(0.0), openvdb::Vec3d(10.0)), 0.5, 10.0, 1.0));
  EXPECT_NE(refusal(stream_bytes({frustum}), "density").find("not linear"), std::string::npos);

  auto empty = openvdb::FloatGrid::create(0.0f);
  empty->setName("density");
  EXPECT_NE(refusal(stream_bytes({empty}), "density").find("no active voxels"), std::string::npos);

  VolumeLimits tight;
  tight.max_voxels = 23;  // the block is 24
  EXPECT_NE(refusal(stream_bytes({block_grid("density", 1.0, {})}), "density", tight).find("more than the limit"),
            std::string::npos);
  // Two active voxels far apart make a dense box beyond 512^3.
  auto sparse = openvdb::FloatGrid::create(0.0f);
  sparse->setName("density");
  sparse->getAccessor().setValue(openvdb::Coord(0, 0, 0), 1.0f);
  sparse->getAccessor().setValue(openvdb::Coord(1000, 1000, 1000), 1.0f);
  EXPECT_NE(refusal(stream_bytes({sparse}), "density").find("more than the limit"), std::string::npos);
}

TEST(VdbImport, RefusesGarbage) {
  EXPECT_NE(refusal("", "density").find("bad magic"), std::string::npos);
  EXPECT_NE(refusal("hello world", "density").find("bad magic"), std::string::npos);
  const std::string good = stream_bytes({block_grid("density", 1.0, {})});
  // Truncated after the magic, and the magic followed by noise.
  // (Its very last bytes are not all needed: a file one byte short still reads.)
  for (std::size_t size : {std::size_t{8}, std::size_t{40}, good.size() / 2})
    EXPECT_FALSE(refusal(good.substr(0, size), "density").empty()) << size;
  std::string noise = good.substr(0, 4) + std::string(200, '\x7f');
  EXPECT_FALSE(refusal(noise, "density").empty());
}

}  // namespace
}  // namespace skyfarm::assets
