// The canonical form of a triangle mesh: joined vertices, dropped degenerate
// triangles, first-use numbering, bounds.
#include "common/assets/triangle_mesh.h"

#include <gtest/gtest.h>

namespace skyfarm::assets {
namespace {

TEST(TriangleMesh, CanonicalFormJoinsDropsAndRenumbers) {
  TriangleMesh m;
  // Two triangles as a triangle soup (6 vertices, 2 shared positions), a
  // repeated-index one, a zero-area one, an out-of-range one and an unused vertex.
  m.positions = {5, 5, 5,  0, 0, 0,  1, 0, 0,  0, 1, 0,  1, 0, 0,  0, 1, 0,  1, 1, 0,  2, 0, 0};
  m.indices = {1, 2, 3,  4, 6, 5,  1, 1, 2,  1, 2, 7,  1, 2, 99};
  const TriangleMesh c = canonicalize_mesh(m);
  ASSERT_EQ(c.triangle_count(), 2u);
  EXPECT_EQ(c.vertex_count(), 4u);
  EXPECT_EQ(c.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(c.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}));
  EXPECT_EQ(canonicalize_mesh(c).indices, c.indices) << "canonical form is a fixed point";
}

TEST(TriangleMesh, NegativeZeroIsJoinedWithZero) {
  TriangleMesh m;
  m.positions = {0, 0, 0,  1, 0, 0,  0, 1, 0,  -0.0, 0, 0,  0, 0, 1};
  m.indices = {0, 1, 2,  3, 1, 4};
  const TriangleMesh c = canonicalize_mesh(m);
  EXPECT_EQ(c.vertex_count(), 4u);
  EXPECT_EQ(c.indices[3], 0u);
}

TEST(TriangleMesh, Bounds) {
  TriangleMesh m;
  m.positions = {-1, 2, 3,  4, -5, 6,  0, 0, -7};
  m.indices = {0, 1, 2};
  const MeshBounds b = mesh_bounds(m);
  EXPECT_EQ(b.min, (std::array<double, 3>{-1, -5, -7}));
  EXPECT_EQ(b.max, (std::array<double, 3>{4, 2, 6}));
}

}  // namespace
}  // namespace skyfarm::assets
