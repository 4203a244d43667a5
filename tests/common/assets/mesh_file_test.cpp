// The skyfarm mesh file: round trip, and the strict checks of the decoder.
#include "common/assets/mesh_file.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>

namespace skyfarm::assets {
namespace {

TriangleMesh tetra() {
  TriangleMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  return m;
}

std::string decode_error(const std::string& bytes, const MeshLimits& limits = {}) {
  TriangleMesh m;
  std::string error;
  if (decode_mesh_file(bytes, limits, &m, &error)) return "<decoded>";
  return error;
}

TEST(MeshFile, RoundTrip) {
  const std::string bytes = encode_mesh_file(tetra());
  EXPECT_EQ(bytes.size(), 16u + 4 * 24 + 4 * 12);
  EXPECT_EQ(bytes.substr(0, 8), "SKYMESH1");
  TriangleMesh back;
  std::string error;
  ASSERT_TRUE(decode_mesh_file(bytes, {}, &back, &error)) << error;
  EXPECT_EQ(back.positions, tetra().positions);
  EXPECT_EQ(back.indices, tetra().indices);
}

TEST(MeshFile, RefusesWhatIsNotExactlyAValidMesh) {
  const std::string good = encode_mesh_file(tetra());
  EXPECT_NE(decode_error("SKYMESH2" + good.substr(8)).find("magic"), std::string::npos);
  EXPECT_NE(decode_error(good.substr(0, good.size() - 1)).find("size"), std::string::npos);
  EXPECT_NE(decode_error(good + "x").find("size"), std::string::npos);
  EXPECT_NE(decode_error(good.substr(0, 10)).find("magic"), std::string::npos);

  std::string bad_index = good;
  const std::uint32_t nine = 9;
  std::memcpy(bad_index.data() + 16 + 96, &nine, 4);
  EXPECT_NE(decode_error(bad_index).find("does not exist"), std::string::npos);

  std::string repeated = good;
  const std::uint32_t zero = 0;
  std::memcpy(repeated.data() + 16 + 96 + 4, &zero, 4);
  EXPECT_NE(decode_error(repeated).find("repeats"), std::string::npos);

  std::string nan = good;
  const double q = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nan.data() + 16 + 8, &q, 8);
  EXPECT_NE(decode_error(nan).find("finite"), std::string::npos);

  std::string huge_counts = good;
  const std::uint32_t big = 0xFFFFFFFFu;
  std::memcpy(huge_counts.data() + 8, &big, 4);
  EXPECT_NE(decode_error(huge_counts).find("vertices"), std::string::npos);
  std::memcpy(huge_counts.data() + 12, &big, 4);
  EXPECT_NE(decode_error(huge_counts).find("triangles"), std::string::npos);

  MeshLimits three;
  three.max_triangles = 3;
  EXPECT_NE(decode_error(good, three).find("limit of 3"), std::string::npos);

  TriangleMesh empty;
  EXPECT_NE(decode_error(encode_mesh_file(empty)).find("no triangles"), std::string::npos);
}

}  // namespace
}  // namespace skyfarm::assets
