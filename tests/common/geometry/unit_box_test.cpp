// The unit box against analytic slab hits: faces and normals from outside
// and inside, edges and corners hit, misses past them, parallel rays.
#include "common/geometry/unit_box.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <random>

namespace skyfarm {
namespace {

constexpr double kInf = INFINITY;

TEST(UnitBox, AxisRaysHitEachFaceWithItsNormal) {
  for (int axis = 0; axis < 3; ++axis)
    for (double s : {-1.0, 1.0}) {
      glm::dvec3 o(0.1, -0.2, 0.15), d(0.0);
      o[axis] = 3.0 * s;
      d[axis] = -s;
      const auto h = intersect_unit_box({o, d}, kInf);
      ASSERT_TRUE(h);
      EXPECT_DOUBLE_EQ(h->t, 2.5);
      glm::dvec3 n(0.0);
      n[axis] = s;
      EXPECT_EQ(h->n, n);
      EXPECT_EQ(h->p[axis], 0.5 * s);
      EXPECT_EQ(h->primitive, static_cast<std::uint32_t>(2 * axis + (s > 0 ? 1 : 0)));
    }
}

TEST(UnitBox, RandomRaysMatchTheFacePointAndFromInsideTheExit) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 20000; ++k) {
    // A point on a random face, approached from a random outside point that
    // sees that face (origin beyond the face's plane).
    const int face = k % 6, axis = face / 2;
    const double side = (face % 2) ? 0.5 : -0.5;
    glm::dvec3 target{0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng)};
    target[axis] = side;
    glm::dvec3 o{2.0 * u(rng), 2.0 * u(rng), 2.0 * u(rng)};
    o[axis] = side * (2.2 + std::abs(u(rng)));
    const glm::dvec3 d = target - o;
    const auto h = intersect_unit_box({o, d}, kInf);
    // The segment o -> target stays beyond the face's plane until target,
    // so the box is entered there.
    ASSERT_TRUE(h) << k;
    EXPECT_NEAR(h->t, 1.0, 1e-14);
    EXPECT_EQ(h->primitive, static_cast<std::uint32_t>(face));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(h->p[a], target[a], 1e-14);
    EXPECT_LT(glm::dot(h->n, d), 0.0);
    // From inside: straight on through target and out the far side.
    const glm::dvec3 inside = 0.4 * target;
    const auto out = intersect_unit_box({inside, target - inside}, kInf);
    ASSERT_TRUE(out);
    EXPECT_NEAR(out->t, 1.0, 1e-14);
    EXPECT_GT(glm::dot(out->n, target - inside), 0.0);
    EXPECT_EQ(out->p[axis], side);
  }
}

TEST(UnitBox, EdgesAndCornersHitJustOutsideMisses) {
  EXPECT_TRUE(intersect_unit_box({{0.5, 0.5, 3.0}, {0, 0, -1}}, kInf));  // along an edge
  EXPECT_TRUE(intersect_unit_box({{2.0, 2.0, 2.0}, {-1, -1, -1}}, kInf));  // at the corner
  EXPECT_FALSE(intersect_unit_box({{std::nextafter(0.5, 1.0), 0.0, 3.0}, {0, 0, -1}}, kInf));
  EXPECT_FALSE(intersect_unit_box({{0.6, 0.0, 3.0}, {0, 0, -1}}, kInf));
  // Grazing a face from outside, inside its plane: touches the face.
  const auto h = intersect_unit_box({{-3.0, 0.1, 0.5}, {1, 0, 0}}, kInf);
  ASSERT_TRUE(h);
  EXPECT_DOUBLE_EQ(h->t, 2.5);
  // Past the box, behind the origin, beyond t_max.
  EXPECT_FALSE(intersect_unit_box({{-3.0, 0.0, 0.0}, {-1, 0, 0}}, kInf));
  EXPECT_FALSE(intersect_unit_box({{-3.0, 0.0, 0.0}, {1, 0, 0}}, 2.4));
  EXPECT_FALSE(intersect_unit_box({{-3.0, 0.0, 0.0}, {1, 1, 0}}, kInf));
}

}  // namespace
}  // namespace skyfarm
