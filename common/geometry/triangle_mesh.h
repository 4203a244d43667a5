// A triangle mesh in its object frame: vertex positions, 3 uint32 indices
// per triangle (counter-clockwise seen from the front, the side its
// geometric normal points to), and optional per-vertex shading normals.
// positions() and indices() are the plain arrays an acceleration structure
// is built over.
//
//   intersect(ray, tri, t_max)  one triangle, watertight (triangle.h); the
//                 hit's p is b0 p0 + b1 p1 + b2 p2 with error
//                 gamma(7) sum |b_i p_i| (PBR 3rd ed., §3.9.6), n the unit
//                 geometric normal of (p1 - p0) x (p2 - p0), uv = (b1, b2),
//                 primitive = tri
//   intersect(ray, t_max)  the nearest over all triangles, brute force (for
//                 tests and tiny meshes; scenes go through a BVH)
//   shading_normal  the normals interpolated and renormalised at (b1, b2),
//                 or the geometric normal when the mesh has none
#pragma once
#include <cstdint>
#include <glm/vec3.hpp>
#include <optional>
#include <vector>

#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

class TriangleMesh {
 public:
  // Throws std::invalid_argument when indices.size() is not a multiple of 3,
  // an index is out of range, a position or normal is not finite, normals
  // is neither empty nor one per position, or there are no triangles.
  TriangleMesh(std::vector<glm::dvec3> positions, std::vector<std::uint32_t> indices,
               std::vector<glm::dvec3> normals = {});

  const std::vector<glm::dvec3>& positions() const { return positions_; }
  const std::vector<std::uint32_t>& indices() const { return indices_; }
  const std::vector<glm::dvec3>& normals() const { return normals_; }
  bool has_normals() const { return !normals_.empty(); }
  std::size_t triangle_count() const { return indices_.size() / 3; }

  std::optional<ShapeHit> intersect(const Ray& ray, std::uint32_t tri, double t_max) const;
  std::optional<ShapeHit> intersect(const Ray& ray, double t_max) const;
  glm::dvec3 geometric_normal(std::uint32_t tri) const;
  glm::dvec3 shading_normal(std::uint32_t tri, double b1, double b2) const;
  double area(std::uint32_t tri) const;

 private:
  std::vector<glm::dvec3> positions_;
  std::vector<std::uint32_t> indices_;
  std::vector<glm::dvec3> normals_;
};

}  // namespace skyfarm
