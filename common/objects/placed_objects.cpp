#include "common/objects/placed_objects.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "common/geometry/placement.h"
#include "common/geometry/rounding_error.h"
#include "common/geometry/unit_box.h"
#include "common/geometry/unit_disc.h"
#include "common/geometry/unit_rectangle.h"
#include "common/geometry/unit_sphere.h"
#include "common/material/surface.h"

namespace skyfarm {
namespace {

std::string object_label(std::size_t i) { return "objects[" + std::to_string(i) + "]"; }

// Every edge shared by exactly two triangles: the mesh encloses a volume.
bool mesh_is_closed(const assets::TriangleMesh& mesh) {
  std::unordered_map<std::uint64_t, int> edges;
  edges.reserve(mesh.indices.size());
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      std::uint64_t a = mesh.indices[3 * t + k], b = mesh.indices[3 * t + (k + 1) % 3];
      if (a > b) std::swap(a, b);
      ++edges[(a << 32) | b];
    }
  return std::all_of(edges.begin(), edges.end(), [](const auto& e) { return e.second == 2; });
}

// The radius of the sphere about the origin around each unit shape.
double unit_bound(ShapeKind shape) {
  switch (shape) {
    case ShapeKind::kSphere:
    case ShapeKind::kDisc: return 1.0;
    case ShapeKind::kRectangle: return std::sqrt(0.5);
    case ShapeKind::kBox: return std::sqrt(0.75);
    case ShapeKind::kMesh: return 0.0;
  }
  return 0.0;
}

std::optional<ShapeHit> intersect_unit_shape(ShapeKind shape, const Ray& ray, double t_max) {
  switch (shape) {
    case ShapeKind::kSphere: return intersect_unit_sphere(ray, t_max);
    case ShapeKind::kDisc: return intersect_unit_disc(ray, t_max);
    case ShapeKind::kRectangle: return intersect_unit_rectangle(ray, t_max);
    case ShapeKind::kBox: return intersect_unit_box(ray, t_max);
    case ShapeKind::kMesh: break;
  }
  return std::nullopt;
}

// Whether the ray (unit direction) can meet the sphere (c, r) at t < t_max.
bool may_hit_sphere(const Ray& ray, const glm::dvec3& c, double r, double t_max) {
  const glm::dvec3 oc = c - ray.o;
  const double b = glm::dot(oc, ray.d);
  const double d2 = glm::dot(oc, oc) - b * b;
  const double r2 = r * r * (1.0 + 1e-9) + 1e-18;  // generous: a reject must never drop a hit
  if (d2 > r2) return false;
  const double half = std::sqrt(std::max(0.0, r2 - d2));
  return b + half > 0.0 && b - half < t_max;
}

glm::dvec3 perpendicular_tangent(const glm::dvec3& n, const glm::dvec3& x, const glm::dvec3& y) {
  glm::dvec3 t = x - glm::dot(x, n) * n;
  if (glm::dot(t, t) < 1e-12 * glm::dot(x, x)) t = y - glm::dot(y, n) * n;
  return glm::normalize(t);
}

}  // namespace

PlacedObjects::PlacedObjects(const std::vector<ObjectSpec>& specs, double ground_radius_m,
                             const assets::MeshSource* meshes)
    : enu_(ground_radius_m) {
  std::map<std::string, std::uint32_t> mesh_index;
  std::vector<accel::MeshArrays> arrays;
  std::vector<accel::Instance> instances;
  objects_.reserve(specs.size());
  for (std::size_t i = 0; i < specs.size(); ++i) {
    const ObjectSpec& spec = specs[i];
    Object o;
    o.shape = spec.shape;
    try {
      o.to_enu = transform_from_placement(spec.placement);
      o.surface = std::make_unique<material::Surface>(spec.material);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(object_label(i) + ": " + e.what());
    }
    o.to_object = o.to_enu.inverse();
    o.bound_centre = spec.placement.translate_m;
    const glm::dvec3 s = glm::abs(spec.placement.scale);
    o.bound_radius = std::max({s.x, s.y, s.z}) * unit_bound(spec.shape);
    o.solid = spec.shape == ShapeKind::kSphere || spec.shape == ShapeKind::kBox;
    if (spec.shape == ShapeKind::kMesh) {
      auto [it, inserted] = mesh_index.try_emplace(spec.asset, static_cast<std::uint32_t>(meshes_.size()));
      if (inserted) {
        if (!meshes) throw std::runtime_error(object_label(i) + ": no source for mesh asset " + spec.asset);
        std::shared_ptr<const assets::TriangleMesh> mesh;
        try {
          mesh = meshes->mesh(spec.asset);
        } catch (const std::exception& e) {
          throw std::runtime_error(object_label(i) + ".asset: " + e.what());
        }
        if (!mesh || mesh->triangle_count() == 0)
          throw std::runtime_error(object_label(i) + ".asset: mesh " + spec.asset + " has no triangles");
        accel::MeshArrays a;
        a.positions.reserve(mesh->vertex_count());
        for (std::size_t v = 0; v < mesh->vertex_count(); ++v)
          a.positions.emplace_back(mesh->positions[3 * v], mesh->positions[3 * v + 1], mesh->positions[3 * v + 2]);
        a.indices = mesh->indices;
        arrays.push_back(std::move(a));
        mesh_closed_.push_back(mesh_is_closed(*mesh));
        meshes_.push_back(std::move(mesh));
      }
      o.mesh = it->second;
      o.solid = mesh_closed_[o.mesh];
      triangles_ += meshes_[o.mesh]->triangle_count();
      instance_of_.push_back(i);
      instances.push_back({o.mesh, o.to_enu.matrix()});
    } else {
      analytic_.push_back(i);
    }
    objects_.push_back(std::move(o));
  }
  if (!instances.empty()) {
    // One build thread: the worker's render threads are busy, and the hits
    // do not depend on it.
    bvh_ = std::make_unique<accel::TriangleBvh>(std::move(arrays), std::move(instances),
                                                accel::BvhBuildOptions{1});
  }
}

PlacedObjects::~PlacedObjects() = default;

std::optional<PlacedObjects::ObjectHit> PlacedObjects::closest(const Ray& enu, double t_max) const {
  std::optional<ObjectHit> best;
  double t_best = t_max;
  for (std::size_t i : analytic_) {
    const Object& o = objects_[i];
    if (!may_hit_sphere(enu, o.bound_centre, o.bound_radius, t_best)) continue;
    // Carried into the object's frame with its direction unnormalised: t is
    // the same number in both frames.
    const std::optional<ShapeHit> h = intersect_unit_shape(o.shape, o.to_object.ray(enu), t_best);
    if (!h) continue;
    best = ObjectHit{o.to_enu.to_parent(*h), i};
    t_best = h->t;
  }
  if (bvh_) {
    const std::optional<accel::BvhHit> h = bvh_->closest_hit(enu.o, enu.d, t_best);
    // closest_hit counts t in (0, t_max]: a hit at exactly t_best is not
    // nearer than the analytic one found there.
    if (h && (!best || h->t < t_best)) {
      const std::size_t i = instance_of_[h->instance];
      const Object& o = objects_[i];
      const assets::TriangleMesh& mesh = *meshes_[o.mesh];
      const std::uint32_t* idx = &mesh.indices[3 * std::size_t{h->primitive}];
      const auto vertex = [&](std::uint32_t k) {
        return glm::dvec3(mesh.positions[3 * k], mesh.positions[3 * k + 1], mesh.positions[3 * k + 2]);
      };
      const glm::dvec3 p0 = vertex(idx[0]), p1 = vertex(idx[1]), p2 = vertex(idx[2]);
      const double b1 = h->u, b2 = h->v, b0 = 1.0 - b1 - b2;
      ShapeHit s;
      s.t = h->t;
      s.p = b0 * p0 + b1 * p1 + b2 * p2;
      s.p_error = rounding_gamma(7) * (glm::abs(b0 * p0) + glm::abs(b1 * p1) + glm::abs(b2 * p2));
      s.n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
      s.uv = {b1, b2};
      s.primitive = h->primitive;
      best = ObjectHit{o.to_enu.to_parent(s), i};
    }
  }
  return best;
}

SurfaceHit PlacedObjects::surface_hit(const ObjectHit& h) const {
  const Object& o = objects_[h.object];
  SurfaceHit s;
  s.t = h.hit.t;
  s.p = enu_.to_world(h.hit.p);
  s.n = h.hit.n;
  s.tangent = perpendicular_tangent(s.n, o.to_enu.direction({1, 0, 0}), o.to_enu.direction({0, 1, 0}));
  s.surface = o.surface.get();
  s.solid = o.solid;
  // The point's own bound (in ENU) and the planet-centred rounding of it and
  // of the offset origin (half an ulp of ~6.4e6 m each, per component).
  const double p_error = std::max({h.hit.p_error.x, h.hit.p_error.y, h.hit.p_error.z});
  const double world_ulp = std::ldexp(1.0, std::ilogb(enu_.observer_radius_m() + std::abs(h.hit.p.z)) - 52);
  s.offset_m = 2.0 * (std::sqrt(3.0) * p_error + 2.0 * world_ulp);
  return s;
}

std::optional<SurfaceHit> PlacedObjects::intersect(const Ray& ray, double t_max) const {
  const std::optional<ObjectHit> h = closest(enu_.to_enu(ray), t_max);
  if (!h) return std::nullopt;
  return surface_hit(*h);
}

bool PlacedObjects::occluded(const Ray& ray, double t_max) const {
  const Ray enu = enu_.to_enu(ray);
  for (std::size_t i : analytic_) {
    const Object& o = objects_[i];
    if (!may_hit_sphere(enu, o.bound_centre, o.bound_radius, t_max)) continue;
    if (intersect_unit_shape(o.shape, o.to_object.ray(enu), t_max)) return true;
  }
  return bvh_ && bvh_->occluded(enu.o, enu.d, t_max);
}

}  // namespace skyfarm
