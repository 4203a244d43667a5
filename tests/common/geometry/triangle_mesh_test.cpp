// TriangleMesh: validation, the plain arrays a BVH is built over, hits
// carrying p, error bound, geometric and shading normals.
#include "common/geometry/triangle_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>

namespace skyfarm {
namespace {

constexpr double kInf = INFINITY;

TriangleMesh two_triangle_square() {
  return TriangleMesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 3},
                      {{0, 0, 1}, {1, 0, 1}, {0, 0, 1}, {0, 0, 1}});
}

TEST(TriangleMesh, ExposesPlainArrays) {
  const TriangleMesh m = two_triangle_square();
  const std::vector<glm::dvec3>& p = m.positions();
  const std::vector<std::uint32_t>& i = m.indices();
  EXPECT_EQ(p.size(), 4u);
  EXPECT_EQ(i.size(), 6u);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_DOUBLE_EQ(m.area(0) + m.area(1), 1.0);
}

TEST(TriangleMesh, RejectsBadInput) {
  EXPECT_THROW(TriangleMesh({{0, 0, 0}}, {0, 0}), std::invalid_argument);
  EXPECT_THROW(TriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 3}), std::invalid_argument);
  EXPECT_THROW(TriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {}), std::invalid_argument);
  EXPECT_THROW(TriangleMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}, {{0, 0, 1}}), std::invalid_argument);
  EXPECT_THROW(TriangleMesh({{0, 0, NAN}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}), std::invalid_argument);
}

TEST(TriangleMesh, NearestHitWithPointNormalAndShadingNormal) {
  const TriangleMesh m = two_triangle_square();
  const auto h = m.intersect({{0.75, 0.25, 2.0}, {0, 0, -0.5}}, kInf);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->primitive, 0u);
  EXPECT_NEAR(h->t, 4.0, 1e-15);
  EXPECT_NEAR(h->p.x, 0.75, 1e-15);
  EXPECT_NEAR(h->p.y, 0.25, 1e-15);
  EXPECT_EQ(h->n, glm::dvec3(0, 0, 1));  // counter-clockwise from +z
  EXPECT_GE(h->p_error.x, 0.0);
  // Barycentrics: p = b0 p0 + b1 p1 + b2 p2 with p1 = (1,0,0), p2 = (1,1,0).
  EXPECT_NEAR(h->uv.x, 0.5, 1e-15);
  EXPECT_NEAR(h->uv.y, 0.25, 1e-15);
  // The shading normal blends vertex 1's tilted normal.
  const glm::dvec3 ns = m.shading_normal(h->primitive, h->uv.x, h->uv.y);
  EXPECT_NEAR(glm::length(ns), 1.0, 1e-15);
  EXPECT_GT(ns.x, 0.1);
  // A mesh without normals shades with the geometric one.
  const TriangleMesh bare({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 2, 1});
  EXPECT_EQ(bare.shading_normal(0, 0.2, 0.2), glm::dvec3(0, 0, -1));
  // The nearer of two stacked triangles.
  const TriangleMesh stack({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}}, {0, 1, 2, 3, 4, 5});
  const auto hs = stack.intersect({{0.2, 0.2, 3.0}, {0, 0, -1}}, kInf);
  ASSERT_TRUE(hs);
  EXPECT_EQ(hs->primitive, 1u);
  EXPECT_NEAR(hs->t, 2.0, 1e-15);
}

}  // namespace
}  // namespace skyfarm
