// PlacedObjects, the production scene objects: against the analytic
// ray-sphere intersection of tests/support/analytic_spheres.h, a mesh
// icosphere against the sphere it approximates, occlusion against the
// closest hit, rays leaving a hit against re-hitting it (acne), and the
// path tracer's Lambertian-sphere closed form through PlacedObjects.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "common/geometry/icosphere.h"
#include "common/material/surface.h"
#include "common/objects/placed_objects.h"
#include "common/render/radiance_probe.h"
#include "tests/support/analytic_spheres.h"
#include "tests/support/flat_diffuse.h"
#include "tests/support/sun_specs.h"
#include "tests/support/sunlit_sphere.h"
#include "tests/support/thin_layer.h"

namespace skyfarm {
namespace {

constexpr double kR = 6360e3;  // the planet radius of these scenes, m

material::SurfaceSpec grey(double albedo) { return testing::flat_diffuse(albedo); }

ObjectSpec object(ShapeKind shape, glm::dvec3 translate, glm::dvec3 scale, glm::dvec3 rotate = glm::dvec3(0.0),
                  std::string asset = {}) {
  ObjectSpec o;
  o.shape = shape;
  o.asset = std::move(asset);
  o.material = grey(0.5);
  o.placement.translate_m = translate;
  o.placement.rotate_deg = rotate;
  o.placement.scale = scale;
  return o;
}

// Meshes by id, from memory.
class MemoryMeshes final : public assets::MeshSource {
 public:
  void add(const std::string& id, const TriangleMesh& m) {
    auto mesh = std::make_shared<assets::TriangleMesh>();
    for (const glm::dvec3& p : m.positions()) mesh->positions.insert(mesh->positions.end(), {p.x, p.y, p.z});
    mesh->indices = m.indices();
    meshes_[id] = std::move(mesh);
  }
  std::shared_ptr<const assets::TriangleMesh> mesh(std::string_view id) const override {
    const auto it = meshes_.find(std::string(id));
    if (it == meshes_.end()) throw std::runtime_error("unknown asset " + std::string(id));
    ++calls;
    return it->second;
  }
  mutable int calls = 0;

 private:
  std::map<std::string, std::shared_ptr<const assets::TriangleMesh>> meshes_;
};

const std::string kIco = "sha256:" + std::string(64, 'a');

// Rays from around a point at the camera's height towards random points near `target`.
std::vector<Ray> rays_towards(const glm::dvec3& target_enu, double spread, int n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 o_enu(u(rng) * 2.0, u(rng) * 2.0, 1.6 + u(rng));
    const glm::dvec3 to = target_enu + spread * glm::dvec3(u(rng), u(rng), u(rng));
    rays.push_back({o_enu + glm::dvec3(0, 0, kR), glm::normalize(to - o_enu)});
  }
  return rays;
}

TEST(PlacedObjects, SphereAgreesWithTheAnalyticIntersection) {
  const glm::dvec3 centre(3.0, 12.0, 0.7);
  const double radius = 0.7;
  const material::Surface surface(grey(0.5));
  const PlacedObjects placed({object(ShapeKind::kSphere, centre, glm::dvec3(radius))}, kR, nullptr);
  // AnalyticSpheres takes centres relative to its observer: the ENU origin.
  const testing::AnalyticSpheres analytic(glm::dvec3(0, 0, kR), {{centre, radius, &surface}});
  EXPECT_FALSE(placed.has_bvh());
  int hits = 0;
  for (const Ray& ray : rays_towards(centre, 1.2, 20000, 1)) {
    const auto a = analytic.intersect(ray, 1e6);
    const auto p = placed.intersect(ray, 1e6);
    ASSERT_EQ(a.has_value(), p.has_value());
    EXPECT_EQ(placed.occluded(ray, 1e6), p.has_value());
    if (!a) continue;
    ++hits;
    EXPECT_NEAR(p->t, a->t, 1e-9 * a->t);
    EXPECT_GT(glm::dot(p->n, a->n), 1.0 - 1e-12);
    EXPECT_NEAR(glm::length(p->p - a->p), 0.0, 1e-7);  // both in planet-centred doubles (ulp 9e-10 m)
    EXPECT_TRUE(p->solid);
    EXPECT_NEAR(glm::dot(p->tangent, p->n), 0.0, 1e-12);
    // Shorter than the hit: nothing in the way.
    EXPECT_FALSE(placed.occluded(ray, 0.999 * a->t));
  }
  EXPECT_GT(hits, 5000);
}

// An icosphere of subdivision s inscribed in the unit sphere: every hit lies
// between the inscribed faces and the sphere, so its t is at least the
// sphere's and at most the t of the sphere shrunk to the faces' smallest
// distance from the centre (cos of the largest face's angular radius).
TEST(PlacedObjects, MeshIcosphereLiesBetweenItsInscribedAndCircumscribedSpheres) {
  const TriangleMesh ico = icosphere(4);
  double inner = 1.0;
  for (std::size_t t = 0; t < ico.triangle_count(); ++t) {
    const auto& idx = ico.indices();
    const glm::dvec3 c = (ico.positions()[idx[3 * t]] + ico.positions()[idx[3 * t + 1]] + ico.positions()[idx[3 * t + 2]]) / 3.0;
    inner = std::min(inner, std::abs(glm::dot(c, ico.geometric_normal(static_cast<std::uint32_t>(t)))));
  }
  MemoryMeshes meshes;
  meshes.add(kIco, ico);
  const glm::dvec3 centre(-4.0, 9.0, 1.0);
  const double radius = 1.0;
  const PlacedObjects placed({object(ShapeKind::kMesh, centre, glm::dvec3(radius), glm::dvec3(17, 5, -3), kIco)},
                             kR, &meshes);
  ASSERT_TRUE(placed.has_bvh());
  EXPECT_EQ(placed.triangle_count(), ico.triangle_count());
  const material::Surface surface(grey(0.5));
  const testing::AnalyticSpheres outer_sphere(glm::dvec3(0, 0, kR), {{centre, radius, &surface}});
  const testing::AnalyticSpheres inner_sphere(glm::dvec3(0, 0, kR), {{centre, radius * inner, &surface}});
  int hits = 0;
  for (const Ray& ray : rays_towards(centre, 0.5 * inner, 5000, 2)) {  // within the inner sphere
    const auto outer = outer_sphere.intersect(ray, 1e6);
    const auto in = inner_sphere.intersect(ray, 1e6);
    const auto p = placed.intersect(ray, 1e6);
    ASSERT_TRUE(outer && in && p);  // aimed inside the inner sphere
    ++hits;
    EXPECT_GE(p->t, outer->t - 1e-9);
    EXPECT_LE(p->t, in->t + 1e-9);
    EXPECT_TRUE(p->solid);
    EXPECT_LT(glm::dot(p->n, ray.d), 0.0);  // outward: towards the camera
  }
  EXPECT_EQ(hits, 5000);
  EXPECT_EQ(meshes.calls, 1);
}

// A ray leaving a hit away from the surface, along the offset the hit gives,
// never meets that surface again on a convex solid (acne), and a ray leaving
// into it meets it again (no leak through the surface).
TEST(PlacedObjects, RaysLeavingAHitNeitherReHitNorLeak) {
  MemoryMeshes meshes;
  meshes.add(kIco, icosphere(3));
  const std::vector<ObjectSpec> specs = {
      object(ShapeKind::kSphere, {0, 8, 0.5}, glm::dvec3(0.5)),
      object(ShapeKind::kBox, {3, 20, 1.0}, {2.0, 1.0, 2.0}, {33, 10, -7}),
      object(ShapeKind::kMesh, {-3, 15, 1.0}, glm::dvec3(1.0), {0, 0, 0}, kIco),
      object(ShapeKind::kSphere, {2000, 20000, 300}, glm::dvec3(500.0)),  // a hill 20 km off
  };
  const PlacedObjects placed(specs, kR, &meshes);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int tested = 0;
  for (const glm::dvec3& target : {specs[0].placement.translate_m, specs[1].placement.translate_m,
                                   specs[2].placement.translate_m, specs[3].placement.translate_m}) {
    for (const Ray& ray : rays_towards(target, 0.3, 2000, 4)) {
      const auto h = placed.intersect(ray, 1e9);
      if (!h) continue;
      const glm::dvec3 n = h->n;  // outward
      // A random direction in the outer hemisphere, and its opposite.
      glm::dvec3 w(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
      w = glm::normalize(w);
      if (glm::dot(w, n) < 0.0) w = -w;
      if (glm::dot(w, n) < 1e-3) continue;
      const Ray out{h->p + n * h->offset_m, w};
      const auto again = placed.intersect(out, 1e9);
      // Convex solids: leaving outward, the ray meets another object or nothing.
      if (again) {
        EXPECT_GT(again->t, 1e-3) << "re-hit at " << again->t;
      }
      const Ray in{h->p - n * h->offset_m, -w};
      const auto inside = placed.intersect(in, 1e9);
      ASSERT_TRUE(inside) << "leaked through";
      EXPECT_GT(glm::dot(inside->n, -w), 0.0);  // the inside of a solid: leaving it
      ++tested;
    }
  }
  EXPECT_GT(tested, 3000);
}

TEST(PlacedObjects, SolidsAndSheets) {
  MemoryMeshes meshes;
  meshes.add(kIco, icosphere(1));
  const std::string quad = "sha256:" + std::string(64, 'b');
  meshes.add(quad, TriangleMesh({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {0, 1, 2, 0, 2, 3}));
  const PlacedObjects placed({object(ShapeKind::kBox, {0, 10, 0.5}, glm::dvec3(1.0)),
                              object(ShapeKind::kDisc, {0, 10, 3}, glm::dvec3(1.0), {0, 90, 0}),
                              object(ShapeKind::kRectangle, {0, 10, 6}, glm::dvec3(1.0), {0, 90, 0}),
                              object(ShapeKind::kMesh, {0, 10, 9}, glm::dvec3(0.5), {0, 0, 0}, kIco),
                              object(ShapeKind::kMesh, {0, 10, 12}, glm::dvec3(0.5), {0, 90, 0}, quad),
                              object(ShapeKind::kMesh, {0, 10, 15}, glm::dvec3(0.5), {0, 0, 0}, kIco)},
                             kR, &meshes);
  EXPECT_EQ(meshes.calls, 2);  // one load per asset, however many objects
  const glm::dvec3 camera(0, 0, kR + 1.6);
  const bool expected[] = {true, false, false, true, false, true};
  for (int i = 0; i < 6; ++i) {
    const glm::dvec3 target(0, 10, i == 0 ? 0.5 : 3.0 * i);
    const Ray ray{camera, glm::normalize(target + glm::dvec3(0, 0, kR) - camera)};
    const auto h = placed.intersect(ray, 1e6);
    ASSERT_TRUE(h) << i;
    EXPECT_EQ(h->solid, expected[i]) << i;
    // The sheets stand upright (pitch 90): their normal +z turned to -y (south).
    if (!expected[i]) {
      EXPECT_NEAR(h->n.y, -1.0, 1e-12) << i;
    }
  }
}

// A closed mesh wound inside out (every triangle reversed) still has its
// normals pointing out of the solid: glass depends on it.
TEST(PlacedObjects, AClosedMeshWoundInsideOutHasOutwardNormals) {
  const TriangleMesh ico = icosphere(2);
  std::vector<std::uint32_t> reversed = ico.indices();
  for (std::size_t t = 0; t < reversed.size(); t += 3) std::swap(reversed[t + 1], reversed[t + 2]);
  MemoryMeshes meshes;
  const std::string inside_out = "sha256:" + std::string(64, 'd');
  meshes.add(kIco, ico);
  meshes.add(inside_out, TriangleMesh(ico.positions(), reversed));
  for (const std::string& id : {kIco, inside_out}) {
    const PlacedObjects placed({object(ShapeKind::kMesh, {0, 10, 1}, glm::dvec3(1.0), {0, 0, 0}, id)}, kR, &meshes);
    for (const Ray& ray : rays_towards({0, 10, 1}, 0.3, 200, 5)) {
      const auto h = placed.intersect(ray, 1e6);
      ASSERT_TRUE(h);
      EXPECT_TRUE(h->solid);
      EXPECT_GT(glm::dot(h->n, h->p - glm::dvec3(0, 10, 1 + kR)), 0.0) << id;
    }
  }
}

TEST(PlacedObjects, AMeshWithoutItsAssetNamesTheObject) {
  MemoryMeshes meshes;
  try {
    PlacedObjects({object(ShapeKind::kSphere, {0, 5, 1}, glm::dvec3(1.0)),
                   object(ShapeKind::kMesh, {0, 5, 1}, glm::dvec3(1.0), {0, 0, 0}, kIco)},
                  kR, &meshes);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("objects[1].asset"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PlacedObjects({object(ShapeKind::kMesh, {0, 5, 1}, glm::dvec3(1.0), {0, 0, 0}, kIco)}, kR, nullptr),
               std::runtime_error);
}

// The path tracer through PlacedObjects: a Lambertian sphere of albedo rho
// under the sun's disk in (near) vacuum has L = rho L_sun sin^2(alpha) cos,
// 0 on its far side (tests/support/sunlit_sphere.h).
TEST(PlacedObjects, LambertianSphereUnderTheSunMatchesTheClosedForm) {
  const double rho = 0.8, sun_zenith = 40.0, camera_up = 1.5;
  AtmosphereSpec spec = testing::thin_hg_layer(1e-12, 1000.0, 0.0);
  Scene scene = Scene::from_specs(spec, testing::sun_spec(sun_zenith, 90.0), Location{0, 0, camera_up}, std::nullopt,
                                  360.0, 830.0);
  const double radius = 1.0;
  const glm::dvec3 centre(0.0, 6.0, 2.0);  // ENU from the ground below the camera
  ObjectSpec ball = object(ShapeKind::kSphere, centre, glm::dvec3(radius));
  ball.material = grey(rho);
  scene.set_objects(std::make_shared<PlacedObjects>(std::vector<ObjectSpec>{ball}, scene.atmosphere().planet_radius_m(),
                                                    nullptr));
  testing::expect_sunlit_lambertian_sphere(scene, centre - glm::dvec3(0, 0, camera_up), radius, rho);
}

}  // namespace
}  // namespace skyfarm
