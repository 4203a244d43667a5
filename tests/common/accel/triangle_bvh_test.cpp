#include "common/accel/triangle_bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "common/accel/ray_triangle.h"

namespace skyfarm::accel {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double uniform(std::mt19937_64& rng, double a, double b) {
  return a + (b - a) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

glm::dvec3 random_unit(std::mt19937_64& rng) {
  const double z = uniform(rng, -1.0, 1.0), phi = uniform(rng, 0.0, 6.283185307179586);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// A soup of n triangles, each within `size` of a centre in [-half, half]^3,
// sharing vertices in strips so edges are met too.
MeshArrays random_mesh(std::mt19937_64& rng, int n, double half, double size) {
  MeshArrays m;
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 c{uniform(rng, -half, half), uniform(rng, -half, half), uniform(rng, -half, half)};
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (int k = 0; k < 4; ++k)
      m.positions.push_back(c + glm::dvec3(uniform(rng, -size, size), uniform(rng, -size, size), uniform(rng, -size, size)));
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base + 2, base + 1, base + 3});
  }
  return m;
}

glm::dmat4 random_transform(std::mt19937_64& rng, const glm::dvec3& translation) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translation);
  m = glm::rotate(m, uniform(rng, 0.0, 6.0), random_unit(rng));
  return glm::scale(m, glm::dvec3(uniform(rng, 0.5, 2.0), uniform(rng, 0.5, 2.0), uniform(rng, 0.5, 2.0)));
}

struct Scene {
  std::vector<MeshArrays> meshes;
  std::vector<Instance> instances;
};

// Three meshes, seven instances: near the origin and one 20 km east.
Scene random_scene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Scene s;
  s.meshes.push_back(random_mesh(rng, 60, 20.0, 6.0));
  s.meshes.push_back(random_mesh(rng, 40, 10.0, 3.0));
  s.meshes.push_back(random_mesh(rng, 50, 30.0, 8.0));
  for (std::uint32_t i = 0; i < 6; ++i)
    s.instances.push_back({i % 3, random_transform(rng, {uniform(rng, -60, 60), uniform(rng, -60, 60), uniform(rng, -20, 40)})});
  s.instances.push_back({0, random_transform(rng, {20000.0, 300.0, 50.0})});
  return s;
}

struct Ray {
  glm::dvec3 o, d;
  double tmax;
};

std::vector<Ray> random_rays(std::uint64_t seed, std::size_t n) {
  std::mt19937_64 rng(seed);
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 o{uniform(rng, -100, 100), uniform(rng, -100, 100), uniform(rng, -100, 100)};
    glm::dvec3 target;
    switch (i % 4) {
      case 0: target = o + random_unit(rng); break;
      case 1: case 2: target = {uniform(rng, -80, 80), uniform(rng, -80, 80), uniform(rng, -40, 60)}; break;
      default: target = {uniform(rng, 19960, 20040), uniform(rng, 260, 340), uniform(rng, 10, 90)}; break;
    }
    // Not unit: t is in units of |dir| and must stay so.
    const glm::dvec3 d = (target - o) * uniform(rng, 0.5, 2.0) / glm::length(target - o);
    const double tmax = (i % 3 == 0) ? uniform(rng, 1.0, 200.0) : kInf;
    rays.push_back({o, d, tmax});
  }
  return rays;
}

// Every triangle of every instance, the same double test: the reference.
std::optional<BvhHit> brute_force(const Scene& s, const Ray& r) {
  std::optional<BvhHit> best;
  for (std::uint32_t i = 0; i < s.instances.size(); ++i) {
    const glm::dmat4 inv = glm::inverse(s.instances[i].object_to_world);
    const glm::dvec3 o = glm::dvec3(inv * glm::dvec4(r.o, 1.0)), d = glm::dvec3(inv * glm::dvec4(r.d, 0.0));
    const MeshArrays& m = s.meshes[s.instances[i].mesh];
    for (std::uint32_t p = 0; p < m.indices.size() / 3; ++p) {
      const auto h = intersect_triangle(o, d, m.positions[m.indices[3 * p]], m.positions[m.indices[3 * p + 1]],
                                        m.positions[m.indices[3 * p + 2]]);
      if (!h || !(h->t > 0.0) || h->t > r.tmax) continue;
      if (best && !(h->t < best->t)) continue;  // ties: the first, i.e. the lowest (instance, primitive)
      best = BvhHit{h->t, i, s.instances[i].mesh, p, h->u, h->v, r.o + h->t * r.d};
    }
  }
  return best;
}

double edge_distance(const BvhHit& h) { return std::min({h.u, h.v, 1.0 - h.u - h.v}); }

// Metres from the hit point to the nearest edge of the hit triangle.
double edge_distance_m(const Scene& s, const BvhHit& h) {
  const MeshArrays& m = s.meshes[h.mesh];
  const glm::dmat4& xf = s.instances[h.instance].object_to_world;
  glm::dvec3 p[3];
  for (int k = 0; k < 3; ++k) p[k] = glm::dvec3(xf * glm::dvec4(m.positions[m.indices[3 * h.primitive + k]], 1.0));
  double best = kInf;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 e = glm::normalize(p[(k + 1) % 3] - p[k]);
    const glm::dvec3 w = h.point - p[k];
    best = std::min(best, glm::length(w - glm::dot(w, e) * e));
  }
  return best;
}

TEST(TriangleBvh, AgreesWithBruteForceOnRandomRays) {
  const Scene s = random_scene(7);
  const TriangleBvh bvh(s.meshes, s.instances);
  const auto rays = random_rays(11, 100000);
  int hits = 0, far_hits = 0, edge_misses = 0;
  for (const Ray& r : rays) {
    const auto want = brute_force(s, r);
    const auto got = bvh.closest_hit(r.o, r.d, r.tmax);
    ASSERT_EQ(bvh.occluded(r.o, r.d, r.tmax), got.has_value());
    if (want.has_value() != got.has_value() || (want && (want->instance != got->instance || want->primitive != got->primitive))) {
      // Embree's float traversal may skip a triangle crossed within float
      // precision of its edge (the precision contract); nothing else.
      // Float rounding is about 1e-7 of the coordinates (ray origin, vertices,
      // transform): 1e-6 of the hit's distance from the frame's origin bounds
      // the band it can move an edge by.
      ASSERT_TRUE(want.has_value());
      EXPECT_LT(edge_distance_m(s, *want), 1e-6 * (1.0 + glm::length(want->point))) << "t " << want->t;
      ++edge_misses;
      continue;
    }
    if (!want) continue;
    ++hits;
    if (want->point.x > 10000.0) ++far_hits;
    // The same double test decides both: t agrees to the last bits (1e-12
    // relative leaves room for nothing but a different evaluation order).
    EXPECT_NEAR(got->t, want->t, 1e-12 * want->t);
    EXPECT_EQ(got->mesh, want->mesh);
    EXPECT_NEAR(got->u, want->u, 1e-12);
    EXPECT_NEAR(got->v, want->v, 1e-12);
    EXPECT_NEAR(glm::length(got->point - want->point), 0.0, 1e-9 * (1.0 + glm::length(want->point)));
  }
  RecordProperty("hits", hits);
  RecordProperty("far_hits", far_hits);
  RecordProperty("edge_misses", edge_misses);
  EXPECT_GT(hits, 20000);    // the test means something: many rays hit
  EXPECT_GT(far_hits, 1000);  // including the instance 20 km away
  EXPECT_LE(edge_misses, 20);  // 1 with these seeds
}

// Every field of two hits, bit for bit.
void expect_same_bits(const std::optional<BvhHit>& a, const std::optional<BvhHit>& b) {
  ASSERT_EQ(a.has_value(), b.has_value());
  if (!a) return;
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a->t), std::bit_cast<std::uint64_t>(b->t));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a->u), std::bit_cast<std::uint64_t>(b->u));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(a->v), std::bit_cast<std::uint64_t>(b->v));
  EXPECT_EQ(a->instance, b->instance);
  EXPECT_EQ(a->primitive, b->primitive);
  EXPECT_EQ(a->mesh, b->mesh);
}

TEST(TriangleBvh, HitsDoNotDependOnBuildThreadsOrRebuilds) {
  Scene s = random_scene(21);
  // Exact ties everywhere: a second instance of the same mesh in the same
  // place, and a mesh whose triangles are all duplicated.
  s.instances.push_back(s.instances[0]);
  MeshArrays twice = s.meshes[1];
  const auto n = static_cast<std::uint32_t>(twice.indices.size());
  for (std::uint32_t k = 0; k < n; ++k) twice.indices.push_back(twice.indices[k]);
  s.meshes.push_back(twice);
  s.instances.push_back({3, s.instances[1].object_to_world});
  const TriangleBvh one(s.meshes, s.instances, {1});
  const TriangleBvh two(s.meshes, s.instances, {2});
  const TriangleBvh all(s.meshes, s.instances);
  const TriangleBvh again(s.meshes, s.instances, {1});
  int ties = 0;
  for (const Ray& r : random_rays(5, 100000)) {
    const auto a = one.closest_hit(r.o, r.d, r.tmax);
    expect_same_bits(a, two.closest_hit(r.o, r.d, r.tmax));
    expect_same_bits(a, all.closest_hit(r.o, r.d, r.tmax));
    expect_same_bits(a, again.closest_hit(r.o, r.d, r.tmax));
    if (!a) continue;
    // The lowest ids win exact ties: the copies never do.
    EXPECT_NE(a->instance, 7u);
    if (a->instance == 8) {
      EXPECT_LT(a->primitive, n / 3);
    }
    if (a->instance == 0 || a->instance == 1) ++ties;
  }
  EXPECT_GT(ties, 1000);
}

TEST(TriangleBvh, InstanceEqualsPreTransformedMesh) {
  std::mt19937_64 rng(3);
  const MeshArrays mesh = random_mesh(rng, 80, 15.0, 5.0);
  const glm::dmat4 xf = random_transform(rng, {12.0, -7.0, 30.0});
  MeshArrays moved = mesh;
  for (glm::dvec3& p : moved.positions) p = glm::dvec3(xf * glm::dvec4(p, 1.0));
  const TriangleBvh instanced({mesh}, {{0, xf}});
  const TriangleBvh baked({moved}, {{0, glm::dmat4(1.0)}});
  int hits = 0;
  for (const Ray& r : random_rays(9, 20000)) {
    const auto a = instanced.closest_hit(r.o, r.d, r.tmax);
    const auto b = baked.closest_hit(r.o, r.d, r.tmax);
    if (a.has_value() != b.has_value() || (a && a->primitive != b->primitive)) {
      // Only where the two roundings disagree about an edge.
      const auto& h = a ? *a : *b;
      EXPECT_LT(edge_distance(h), 1e-9);
      continue;
    }
    if (!a) continue;
    ++hits;
    EXPECT_NEAR(a->t, b->t, 1e-10 * a->t);
    EXPECT_NEAR(a->u, b->u, 1e-9);
    EXPECT_NEAR(a->v, b->v, 1e-9);
  }
  EXPECT_GT(hits, 1000);
}

TEST(TriangleBvh, FarObjectHitInDoublePrecision) {
  // A large triangle 20 km north, facing the observer; rays from near the
  // origin: t and the point are exact to double rounding, not to float's
  // 2 mm at 20 km.
  const MeshArrays wall{{{-500.0, 20000.0, -500.0}, {500.0, 20000.0, -500.0}, {0.0, 20000.0, 800.0}}, {0, 1, 2}};
  const TriangleBvh bvh({wall}, {{0, glm::dmat4(1.0)}});
  std::mt19937_64 rng(1);
  for (int i = 0; i < 1000; ++i) {
    const glm::dvec3 o{uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, 0, 2)};
    const glm::dvec3 target{uniform(rng, -100, 100), 20000.0, uniform(rng, -100, 100)};
    const glm::dvec3 d = glm::normalize(target - o);
    const auto h = bvh.closest_hit(o, d, kInf);
    ASSERT_TRUE(h.has_value());
    EXPECT_NEAR(h->t, (20000.0 - o.y) / d.y, 1e-11 * h->t);
    EXPECT_NEAR(h->point.y, 20000.0, 1e-8);
    EXPECT_NEAR(h->point.x, target.x, 1e-7);
  }
}

TEST(TriangleBvh, TmaxBoundsHitsAndOcclusion) {
  const MeshArrays quad{{{-1, -1, 5}, {1, -1, 5}, {-1, 1, 5}, {1, 1, 5}}, {0, 1, 2, 2, 1, 3}};
  const TriangleBvh bvh({quad}, {{0, glm::dmat4(1.0)}});
  const glm::dvec3 o{0.1, 0.2, 0.0}, up{0, 0, 1};
  EXPECT_FALSE(bvh.closest_hit(o, up, 4.999).has_value());
  EXPECT_FALSE(bvh.occluded(o, up, 4.999));
  ASSERT_TRUE(bvh.closest_hit(o, up, 5.0).has_value());
  EXPECT_TRUE(bvh.occluded(o, up, 5.0));
  EXPECT_EQ(bvh.closest_hit(o, up, kInf)->t, 5.0);
  EXPECT_FALSE(bvh.closest_hit(o, -up, kInf).has_value());  // behind the origin
  EXPECT_FALSE(bvh.occluded(o, -up, kInf));
}

TEST(TriangleBvh, EmptySceneBuildsNothing) {
  const TriangleBvh none({}, {});
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(none.closest_hit({0, 0, 0}, {0, 0, 1}, kInf).has_value());
  EXPECT_FALSE(none.occluded({0, 0, 0}, {0, 0, 1}, kInf));
  const MeshArrays tri{{{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}}, {0, 1, 2}};
  EXPECT_TRUE(TriangleBvh({tri}, {}).empty());                      // a mesh no instance places
  EXPECT_TRUE(TriangleBvh({MeshArrays{}}, {{0, glm::dmat4(1.0)}}).empty());  // an instance of nothing
  EXPECT_FALSE(TriangleBvh({tri}, {{0, glm::dmat4(1.0)}}).empty());
}

TEST(TriangleBvh, RejectsBadInput) {
  const MeshArrays tri{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2}};
  EXPECT_THROW(TriangleBvh({tri}, {{1, glm::dmat4(1.0)}}), std::invalid_argument);
  EXPECT_THROW(TriangleBvh({MeshArrays{tri.positions, {0, 1, 3}}}, {{0, glm::dmat4(1.0)}}), std::invalid_argument);
  EXPECT_THROW(TriangleBvh({MeshArrays{tri.positions, {0, 1}}}, {{0, glm::dmat4(1.0)}}), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm::accel
