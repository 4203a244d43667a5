// The icosphere: counts, a closed and consistently outward-wound surface,
// and hits against the analytic unit sphere within the mesh's sagitta: the
// mesh lies between the unit sphere and the sphere of its smallest face
// distance r_min, so a ray's mesh hit lies between its hits of the two.
#include "common/geometry/icosphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <map>
#include <random>
#include <stdexcept>

#include "common/geometry/unit_sphere.h"

namespace skyfarm {
namespace {

constexpr double kInf = INFINITY;

TEST(Icosphere, CountsAndAClosedOutwardSurface) {
  for (int s = 0; s <= 3; ++s) {
    const TriangleMesh m = icosphere(s);
    const std::size_t f = 20u << (2 * s);
    EXPECT_EQ(m.triangle_count(), f);
    EXPECT_EQ(m.positions().size(), 10u * (1u << (2 * s)) + 2u);
    ASSERT_TRUE(m.has_normals());
    for (const auto& p : m.positions()) EXPECT_NEAR(glm::length(p), 1.0, 1e-15);
    // Every directed edge appears once and its reverse once: closed, and
    // neighbours wound the same way.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    double area = 0.0;
    for (std::uint32_t t = 0; t < m.triangle_count(); ++t) {
      for (int k = 0; k < 3; ++k) ++directed[{m.indices()[3 * t + k], m.indices()[3 * t + (k + 1) % 3]}];
      const glm::dvec3 c = (m.positions()[m.indices()[3 * t]] + m.positions()[m.indices()[3 * t + 1]] +
                            m.positions()[m.indices()[3 * t + 2]]);
      EXPECT_GT(glm::dot(m.geometric_normal(t), c), 0.0);  // counter-clockwise from outside
      area += m.area(t);
    }
    for (const auto& [e, count] : directed) {
      EXPECT_EQ(count, 1);
      EXPECT_EQ(directed.count({e.second, e.first}), 1u);
    }
    EXPECT_EQ(m.positions().size() - directed.size() / 2 + f, 2u);  // Euler
    EXPECT_LT(area, 4.0 * M_PI);
  }
  EXPECT_THROW(icosphere(-1), std::invalid_argument);
  EXPECT_THROW(icosphere(9), std::invalid_argument);
}

double smallest_face_distance(const TriangleMesh& m) {
  double r_min = 1.0;
  for (std::uint32_t t = 0; t < m.triangle_count(); ++t)
    r_min = std::min(r_min, glm::dot(m.geometric_normal(t), m.positions()[m.indices()[3 * t]]));
  return r_min;
}

TEST(Icosphere, HitsAgreeWithTheSphereWithinTheSagitta) {
  const TriangleMesh m = icosphere(4);
  const double r_min = smallest_face_distance(m);
  const double sagitta = 1.0 - r_min;
  EXPECT_GT(sagitta, 1e-4);
  EXPECT_LT(sagitta, 2e-3);
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto random_unit = [&] {
    const double z = 1.0 - 2.0 * u(rng), phi = 2.0 * M_PI * u(rng), r = std::sqrt(1.0 - z * z);
    return glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
  };
  int radial = 0, oblique = 0;
  for (int k = 0; k < 800; ++k) {
    const glm::dvec3 o = random_unit() * (1.5 + 3.0 * u(rng));
    // Radial rays: the mesh is hit between t_s and t_s + sagitta.
    {
      const Ray r{o, -o / glm::length(o)};
      const auto s = intersect_unit_sphere(r, kInf);
      const auto h = m.intersect(r, kInf);
      ASSERT_TRUE(s && h);
      EXPECT_GE(h->t, s->t - 1e-12);
      EXPECT_LE(h->t, s->t + sagitta + 1e-12);
      ++radial;
    }
    // Oblique rays: t_sphere <= t_mesh <= t_inner sphere (when it is hit);
    // rays missing the unit sphere miss the mesh.
    const glm::dvec3 target = random_unit() * 1.1 * std::cbrt(u(rng));
    const Ray r{o, glm::normalize(target - o)};
    const auto s = intersect_unit_sphere(r, kInf);
    const auto h = m.intersect(r, kInf);
    if (!s) {
      EXPECT_FALSE(h);
      continue;
    }
    const auto inner = intersect_unit_sphere({r.o / r_min, r.d / r_min}, kInf);  // sphere of radius r_min
    if (inner) {
      ASSERT_TRUE(h) << k;
      EXPECT_LE(h->t, inner->t + 1e-12);
      ++oblique;
    }
    if (h) {
      EXPECT_GE(h->t, s->t - 1e-12);
      EXPECT_NEAR(glm::length(h->p), 1.0, sagitta + 1e-12);
      EXPECT_LT(glm::dot(h->n, r.d), 0.0);
    }
  }
  EXPECT_EQ(radial, 800);
  EXPECT_GT(oblique, 250);
  RecordProperty("sagitta_s4", std::to_string(sagitta));
}

}  // namespace
}  // namespace skyfarm
