// The watertight triangle test: hits against barycentric construction, and
// rays through shared edges and vertices of a closed mesh never slip
// through (a ray through an edge hits one of its two triangles, through a
// vertex one of its fan), far from the origin and at any direction.
#include "common/geometry/triangle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <map>
#include <random>
#include <vector>

#include "common/geometry/icosphere.h"

namespace skyfarm {
namespace {

constexpr double kInf = INFINITY;

TEST(Triangle, HitsMatchTheBarycentricsAimedAt) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0), v(0.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 p0{u(rng), u(rng), u(rng)}, p1{u(rng), u(rng), u(rng)}, p2{u(rng), u(rng), u(rng)};
    // Barycentrics in [-0.2, 1.2]: some outside.
    const double b1 = 1.4 * v(rng) - 0.2, b2 = 1.4 * v(rng) - 0.2, b0 = 1.0 - b1 - b2;
    const glm::dvec3 target = b0 * p0 + b1 * p1 + b2 * p2;
    const glm::dvec3 o{4.0 * u(rng), 4.0 * u(rng), 4.0 * u(rng)};
    const auto h = intersect_triangle({o, target - o}, p0, p1, p2, kInf);
    const double margin = std::min({b0, b1, b2});
    const glm::dvec3 normal = glm::cross(p1 - p0, p2 - p0);
    // Skip ambiguous targets: at an edge, or rays nearly in the plane.
    if (std::abs(margin) < 1e-9 ||
        std::abs(glm::dot(glm::normalize(normal), glm::normalize(target - o))) < 1e-6)
      continue;
    ASSERT_EQ(h.has_value(), margin > 0.0) << k;
    if (!h) continue;
    ++hits;
    EXPECT_NEAR(h->t, 1.0, 1e-9);
    EXPECT_NEAR(h->b1, b1, 1e-9);
    EXPECT_NEAR(h->b2, b2, 1e-9);
    EXPECT_NEAR(h->b0 + h->b1 + h->b2, 1.0, 1e-14);
  }
  EXPECT_GT(hits, 5000);
}

TEST(Triangle, BehindParallelAndBeyondTMaxMiss) {
  const glm::dvec3 p0{0, 0, 0}, p1{1, 0, 0}, p2{0, 1, 0};
  EXPECT_TRUE(intersect_triangle({{0.2, 0.2, 1}, {0, 0, -1}}, p0, p1, p2, kInf));
  EXPECT_TRUE(intersect_triangle({{0.2, 0.2, -1}, {0, 0, 1}}, p0, p1, p2, kInf));  // back face
  EXPECT_FALSE(intersect_triangle({{0.2, 0.2, 1}, {0, 0, 1}}, p0, p1, p2, kInf));
  EXPECT_FALSE(intersect_triangle({{0.2, 0.2, 1}, {0, 0, -1}}, p0, p1, p2, 0.99));
  EXPECT_FALSE(intersect_triangle({{-1, 0.2, 0}, {1, 0, 0}}, p0, p1, p2, kInf));  // in its plane
  EXPECT_FALSE(intersect_triangle({{0.6, 0.6, 1}, {0, 0, -1}}, p0, p1, p2, kInf));
  // A ray starting on the triangle does not hit it (t > its rounding bound).
  EXPECT_FALSE(intersect_triangle({{0.2, 0.2, 0}, {0.3, -0.1, 1}}, p0, p1, p2, kInf));
}

struct Adjacency {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edge;
  std::vector<std::vector<std::uint32_t>> fan;
};

Adjacency adjacency(const TriangleMesh& m) {
  Adjacency a;
  a.fan.resize(m.positions().size());
  for (std::uint32_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = m.indices()[3 * t + k], j = m.indices()[3 * t + (k + 1) % 3];
      a.edge[{std::min(i, j), std::max(i, j)}].push_back(t);
      a.fan[i].push_back(t);
    }
  return a;
}

bool hits_any(const Ray& r, const std::vector<glm::dvec3>& p, const std::vector<std::uint32_t>& idx,
              const std::vector<std::uint32_t>& tris) {
  for (std::uint32_t t : tris)
    if (intersect_triangle(r, p[idx[3 * t]], p[idx[3 * t + 1]], p[idx[3 * t + 2]], kInf)) return true;
  return false;
}

TEST(Triangle, WatertightAtSharedEdgesAndVertices) {
  // An icosphere moved far off the origin and scaled, so the vertices carry
  // rounding in every bit.
  const TriangleMesh unit = icosphere(2);
  std::vector<glm::dvec3> p = unit.positions();
  const glm::dvec3 centre{1234.567, -890.123, 456.789};
  for (auto& q : p) q = centre + 3.7 * q;
  const std::vector<std::uint32_t>& idx = unit.indices();
  const Adjacency adj = adjacency(unit);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const auto& [e, tris] : adj.edge) {
    ASSERT_EQ(tris.size(), 2u);
    edges.push_back(e);
  }

  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto random_unit = [&] {
    const double z = 1.0 - 2.0 * u(rng), phi = 6.283185307179586 * u(rng), r = std::sqrt(1.0 - z * z);
    return glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
  };
  int edge_misses = 0, vertex_misses = 0;
  const int n = 600000;  // 1.2 million rays
  for (int k = 0; k < n; ++k) {
    const bool at_vertex = k % 4 == 0;
    glm::dvec3 target;
    const std::vector<std::uint32_t>* tris;
    if (at_vertex) {
      const auto v = static_cast<std::uint32_t>(k / 4 % p.size());
      target = p[v];
      tris = &adj.fan[v];
    } else {
      const auto& e = edges[k % edges.size()];
      const double s = u(rng);
      target = (1.0 - s) * p[e.first] + s * p[e.second];
      tris = &adj.edge.at(e);
    }
    // From inside the sphere through the target, and from outside back in.
    const glm::dvec3 inner = centre + 2.5 * std::cbrt(u(rng)) * random_unit();
    const glm::dvec3 d = target - inner;
    const glm::dvec3 outer = target + (0.5 + 20.0 * u(rng)) * d;
    const bool in_hit = hits_any({inner, d}, p, idx, *tris);
    const bool out_hit = hits_any({outer, -d * (0.1 + u(rng))}, p, idx, *tris);
    (at_vertex ? vertex_misses : edge_misses) += !in_hit + !out_hit;
  }
  EXPECT_EQ(edge_misses, 0);
  EXPECT_EQ(vertex_misses, 0);
}

}  // namespace
}  // namespace skyfarm
