// The unit disc and the unit rectangle (the plane z = 0) against analytic
// hits: t = -o_z / d_z, the boundary included, both sides, parallel rays,
// uniform area samples.
#include "common/geometry/unit_disc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <random>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

constexpr double kInf = INFINITY;

TEST(UnitDisc, HitsMatchThePlaneAndTheRadius) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 o{3.0 * u(rng), 3.0 * u(rng), 5.0 * u(rng)};
    const glm::dvec3 target{1.3 * u(rng), 1.3 * u(rng), 0.0};
    const glm::dvec3 d = (target - o) * (0.5 + std::abs(u(rng)));
    const auto h = intersect_unit_disc({o, d}, kInf);
    const bool inside = glm::length(target) <= 1.0;
    if (o.z == 0.0) continue;
    ASSERT_EQ(h.has_value(), inside) << k;
    if (!h) continue;
    ++hits;
    EXPECT_NEAR(h->t, -o.z / d.z, 1e-15 * std::abs(o.z / d.z));
    EXPECT_EQ(h->p.z, 0.0);
    EXPECT_NEAR(h->p.x, target.x, 1e-14);
    EXPECT_NEAR(h->p.y, target.y, 1e-14);
    EXPECT_EQ(h->n, glm::dvec3(0, 0, 1));  // not flipped to face the ray
    EXPECT_NEAR(h->uv.x, glm::length(target), 1e-14);
  }
  EXPECT_GT(hits, 5000);
}

TEST(UnitDisc, ParallelAndBehindMiss) {
  EXPECT_FALSE(intersect_unit_disc({{-2, 0, 0.1}, {1, 0, 0}}, kInf));
  EXPECT_FALSE(intersect_unit_disc({{-2, 0, 0.0}, {1, 0, 0}}, kInf));  // in the plane: no area hit
  EXPECT_FALSE(intersect_unit_disc({{0, 0, 1}, {0, 0, 1}}, kInf));
  EXPECT_FALSE(intersect_unit_disc({{0, 0, 1}, {0, 0, -1}}, 0.999));
  EXPECT_TRUE(intersect_unit_disc({{0, 0, -1}, {0, 0, 1}}, kInf));  // from below
  // The rim belongs to the disc.
  EXPECT_TRUE(intersect_unit_disc({{1, 0, 1}, {0, 0, -1}}, kInf));
  EXPECT_FALSE(intersect_unit_disc({{std::nextafter(1.0, 2.0), 0, 1}, {0, 0, -1}}, kInf));
  // Grazing: nearly parallel, still exact.
  const auto h = intersect_unit_disc({{-1e6, 0.3, 1e-3}, {1.0, 0.0, -1e-9}}, kInf);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->p.x, 0.0, 1e-9);
}

TEST(UnitDisc, AreaSamplesAreUniform) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 200000;
  int inner = 0, first_quadrant = 0;
  for (int k = 0; k < n; ++k) {
    const AreaSample s = sample_unit_disc({u(rng), u(rng)});
    EXPECT_LE(glm::length(s.p), 1.0 + 1e-15);
    EXPECT_EQ(s.p.z, 0.0);
    EXPECT_DOUBLE_EQ(s.pdf_area, 1.0 / kPi);
    inner += glm::length(s.p) < 0.5;  // a quarter of the area
    first_quadrant += s.p.x > 0 && s.p.y > 0;
  }
  EXPECT_NEAR(double(inner) / n, 0.25, 5.0 * std::sqrt(0.1875 / n));
  EXPECT_NEAR(double(first_quadrant) / n, 0.25, 5.0 * std::sqrt(0.1875 / n));
}

}  // namespace
}  // namespace skyfarm
