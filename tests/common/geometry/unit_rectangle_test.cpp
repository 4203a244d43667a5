// The unit rectangle against analytic hits: the square's edges included,
// both sides, parallel rays, uniform samples.
#include "common/geometry/unit_rectangle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace skyfarm {
namespace {

constexpr double kInf = INFINITY;

TEST(UnitRectangle, HitsInsideTheSquareOnly) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 o{2.0 * u(rng), 2.0 * u(rng), 4.0 * u(rng)};
    const glm::dvec3 target{0.7 * u(rng), 0.7 * u(rng), 0.0};
    const glm::dvec3 d = target - o;
    const auto h = intersect_unit_rectangle({o, d}, kInf);
    const bool inside = std::abs(target.x) <= 0.5 && std::abs(target.y) <= 0.5;
    // Targets within rounding of an edge are ambiguous.
    if (std::abs(std::abs(target.x) - 0.5) < 1e-12 || std::abs(std::abs(target.y) - 0.5) < 1e-12) continue;
    ASSERT_EQ(h.has_value(), inside) << k;
    if (!h) continue;
    ++hits;
    EXPECT_NEAR(h->t, 1.0, 1e-14);
    EXPECT_EQ(h->p.z, 0.0);
    EXPECT_NEAR(h->uv.x, target.x + 0.5, 1e-14);
    EXPECT_NEAR(h->uv.y, target.y + 0.5, 1e-14);
    EXPECT_EQ(h->n, glm::dvec3(0, 0, 1));
  }
  EXPECT_GT(hits, 5000);
}

TEST(UnitRectangle, EdgesAndCornersBelongToTheSquare) {
  EXPECT_TRUE(intersect_unit_rectangle({{0.5, 0.5, 1}, {0, 0, -1}}, kInf));
  EXPECT_TRUE(intersect_unit_rectangle({{-0.5, 0.0, -1}, {0, 0, 1}}, kInf));
  EXPECT_FALSE(intersect_unit_rectangle({{std::nextafter(0.5, 1.0), 0, 1}, {0, 0, -1}}, kInf));
  EXPECT_FALSE(intersect_unit_rectangle({{0, 0, 1}, {1, 0, 0}}, kInf));
}

TEST(UnitRectangle, SamplesCoverTheSquare) {
  const AreaSample s = sample_unit_rectangle({0.25, 0.75});
  EXPECT_EQ(s.p, glm::dvec3(-0.25, 0.25, 0.0));
  EXPECT_EQ(s.pdf_area, 1.0);
  EXPECT_EQ(s.n, glm::dvec3(0, 0, 1));
}

}  // namespace
}  // namespace skyfarm
