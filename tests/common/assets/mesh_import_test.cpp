// Import of the small files of tests/support/mesh_files.h in every format,
// in this process (the server runs the same code in a child).
#include "common/assets/mesh_import.h"

#include <gtest/gtest.h>

#include "tests/support/mesh_files.h"

namespace skyfarm::assets {
namespace {

using namespace skyfarm::testing;

TriangleMesh imported(const std::string& bytes, const std::string& format, const MeshLimits& limits = {}) {
  TriangleMesh m;
  std::string error;
  EXPECT_TRUE(import_mesh(bytes, format, limits, &m, &error)) << format << ": " << error;
  return m;
}

std::string import_error(const std::string& bytes, const std::string& format, const MeshLimits& limits = {}) {
  TriangleMesh m;
  std::string error;
  if (import_mesh(bytes, format, limits, &m, &error)) return "<imported>";
  EXPECT_FALSE(error.empty());
  return error;
}

TEST(MeshImport, CubeObjIsTriangulatedAndJoined) {
  const TriangleMesh m = imported(cube_obj(), "obj");
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_EQ(m.vertex_count(), 8u);
  const MeshBounds b = mesh_bounds(m);
  EXPECT_EQ(b.min, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(b.max, (std::array<double, 3>{1, 1, 1}));
}

TEST(MeshImport, TetrahedronInEveryFormat) {
  const std::pair<std::string, std::string> files[] = {
      {"obj", tetra_obj()},        {"ply", tetra_ply_ascii()}, {"ply", tetra_ply_binary()},
      {"stl", tetra_stl_binary()}, {"stl", tetra_stl_ascii()}, {"gltf", tetra_gltf()},
      {"glb", tetra_glb()}};
  for (const auto& [format, bytes] : files) {
    SCOPED_TRACE(format);
    const TriangleMesh m = imported(bytes, format);
    EXPECT_EQ(m.triangle_count(), 4u);
    EXPECT_EQ(m.vertex_count(), 4u) << "identical vertices joined (STL repeats them per facet)";
    const MeshBounds b = mesh_bounds(m);
    const double x0 = format == "gltf" || format == "glb" ? 10 : 0;  // the node's translation
    EXPECT_EQ(b.min, (std::array<double, 3>{x0, 0, 0}));
    EXPECT_EQ(b.max, (std::array<double, 3>{x0 + 1, 1, 1}));
    EXPECT_EQ(detect_mesh_format(bytes), format);
  }
}

TEST(MeshImport, ClearErrors) {
  EXPECT_NE(import_error(cube_obj(), "fbx").find("unknown mesh format"), std::string::npos);
  EXPECT_NE(import_error("", "obj").find("empty"), std::string::npos);
  MeshLimits small;
  small.max_triangles = 11;
  EXPECT_NE(import_error(cube_obj(), "obj", small).find("limit of 11"), std::string::npos);
  EXPECT_NE(import_error("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "obj").find("no triangles"), std::string::npos);
  EXPECT_NE(import_error("ply\nformat ascii 1.0\nelement vertex 999999999\nend_header\n", "ply").find("more than the file"),
            std::string::npos);
  EXPECT_NE(import_error(tetra_glb().substr(0, 40), "glb"), "<imported>");
  // A PLY body named as STL reaches the STL reader only.
  EXPECT_NE(import_error(tetra_ply_ascii(), "stl"), "<imported>");
}

TEST(MeshImport, DetectsNothingInNoise) {
  EXPECT_EQ(detect_mesh_format(std::string("\x01\x02\x03 hello", 9)), std::nullopt);
  EXPECT_EQ(detect_mesh_format(""), std::nullopt);
}

}  // namespace
}  // namespace skyfarm::assets
