// The unit sphere against the closed-form roots in long double: rays from
// outside and inside in many directions, unnormalised directions, grazing
// and tangent rays, misses; uniform area samples.
#include "common/geometry/unit_sphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <random>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

constexpr double kInf = INFINITY;

// Smallest root > 0 of |o + t d|^2 = 1 in long double; -1 for none.
long double expected_t(const glm::dvec3& o, const glm::dvec3& d) {
  const long double a = (long double)d.x * d.x + (long double)d.y * d.y + (long double)d.z * d.z;
  const long double b = (long double)o.x * d.x + (long double)o.y * d.y + (long double)o.z * d.z;
  const long double c = (long double)o.x * o.x + (long double)o.y * o.y + (long double)o.z * o.z - 1.0L;
  const long double disc = b * b - a * c;
  if (disc < 0) return -1;
  const long double s = std::sqrt(disc);
  const long double t0 = (-b - s) / a, t1 = (-b + s) / a;
  return t0 > 0 ? t0 : (t1 > 0 ? t1 : -1);
}

glm::dvec3 random_unit(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double z = 1.0 - 2.0 * u(rng), phi = 2.0 * kPi * u(rng), r = std::sqrt(1.0 - z * z);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

TEST(UnitSphere, HitsFromOutsideMatchClosedForm) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 o = random_unit(rng) * (1.01 + 20.0 * u(rng));
    // Aim at a random point of the ball of radius 1.3: some miss.
    const glm::dvec3 target = random_unit(rng) * (1.3 * std::cbrt(u(rng)));
    const glm::dvec3 d = (target - o) * (0.25 + 4.0 * u(rng));  // any length
    const long double t_exp = expected_t(o, d);
    const auto h = intersect_unit_sphere({o, d}, kInf);
    ASSERT_EQ(h.has_value(), t_exp > 0) << k;
    if (!h) continue;
    ++hits;
    EXPECT_NEAR(h->t, (double)t_exp, 1e-12 * (double)t_exp);
    EXPECT_NEAR(glm::length(h->p), 1.0, 1e-15);
    EXPECT_EQ(h->n, h->p);
    EXPECT_LT(glm::dot(h->n, d), 0.0);  // entered from outside
    EXPECT_LE(glm::length(h->p - (o + h->t * d)), 1e-12 * glm::length(o));
  }
  EXPECT_GT(hits, 5000);
}

TEST(UnitSphere, HitsFromInsideLeaveThroughTheFarSide) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 o = random_unit(rng) * (0.999 * std::cbrt(u(rng)));
    const glm::dvec3 d = random_unit(rng);
    const auto h = intersect_unit_sphere({o, d}, kInf);
    ASSERT_TRUE(h.has_value()) << k;  // from inside every ray leaves
    EXPECT_NEAR(h->t, (double)expected_t(o, d), 1e-13);
    EXPECT_GT(glm::dot(h->n, d), 0.0);
  }
}

TEST(UnitSphere, TangentAndGrazingRaysDecideByClosestApproach) {
  // A ray along x at height z = h: hits for h < 1, misses for h > 1.
  for (double h : {0.0, 0.5, 0.9, 0.999999, 1.0 - 1e-12}) {
    const auto hit = intersect_unit_sphere({{-5.0, 0.0, h}, {1.0, 0.0, 0.0}}, kInf);
    ASSERT_TRUE(hit) << h;
    EXPECT_NEAR(hit->t, 5.0 - std::sqrt((1.0 - h) * (1.0 + h)), 1e-12) << h;
  }
  for (double h : {1.0 + 1e-12, 1.000001, 1.5, -1.01})
    EXPECT_FALSE(intersect_unit_sphere({{-5.0, 0.0, h}, {1.0, 0.0, 0.0}}, kInf)) << h;
  // Behind the origin, or beyond t_max: no hit.
  EXPECT_FALSE(intersect_unit_sphere({{5.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, kInf));
  EXPECT_FALSE(intersect_unit_sphere({{-5.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, 3.99));
  EXPECT_TRUE(intersect_unit_sphere({{-5.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, 4.01));
}

TEST(UnitSphere, UvFollowsAzimuthAndPolarAngle) {
  const auto h = intersect_unit_sphere({{0.0, 5.0, 0.0}, {0.0, -1.0, 0.0}}, kInf);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->uv.x, 0.25, 1e-15);  // +y: phi = pi / 2
  EXPECT_NEAR(h->uv.y, 0.5, 1e-15);   // equator
}

TEST(UnitSphere, AreaSamplesAreUniform) {
  // Mean of z and z^2 over the sphere: 0 and 1/3; the fraction in a cap of
  // height 0.2: 0.1 (Archimedes).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 200000;
  double sz = 0, sz2 = 0;
  int cap = 0;
  for (int k = 0; k < n; ++k) {
    const AreaSample s = sample_unit_sphere({u(rng), u(rng)});
    EXPECT_NEAR(glm::length(s.p), 1.0, 1e-15);
    EXPECT_DOUBLE_EQ(s.pdf_area, 1.0 / (4.0 * kPi));
    sz += s.p.z;
    sz2 += s.p.z * s.p.z;
    cap += s.p.z > 0.8;
  }
  EXPECT_NEAR(sz / n, 0.0, 5.0 * std::sqrt(1.0 / 3.0 / n));
  EXPECT_NEAR(sz2 / n, 1.0 / 3.0, 5.0 * std::sqrt(0.09 / n));
  EXPECT_NEAR(double(cap) / n, 0.1, 5.0 * std::sqrt(0.09 / n));
}

}  // namespace
}  // namespace skyfarm
