#include "common/geometry/triangle_mesh.h"

#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <stdexcept>

#include "common/geometry/rounding_error.h"
#include "common/geometry/triangle.h"

namespace skyfarm {
namespace {

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

TriangleMesh::TriangleMesh(std::vector<glm::dvec3> positions, std::vector<std::uint32_t> indices,
                           std::vector<glm::dvec3> normals)
    : positions_(std::move(positions)), indices_(std::move(indices)), normals_(std::move(normals)) {
  if (indices_.empty() || indices_.size() % 3 != 0)
    throw std::invalid_argument("triangle mesh: indices must be a non-empty multiple of 3");
  for (std::uint32_t i : indices_)
    if (i >= positions_.size()) throw std::invalid_argument("triangle mesh: index out of range");
  for (const auto& p : positions_)
    if (!finite(p)) throw std::invalid_argument("triangle mesh: position not finite");
  if (!normals_.empty() && normals_.size() != positions_.size())
    throw std::invalid_argument("triangle mesh: normals must be empty or one per position");
  for (const auto& n : normals_)
    if (!finite(n)) throw std::invalid_argument("triangle mesh: normal not finite");
}

std::optional<ShapeHit> TriangleMesh::intersect(const Ray& ray, std::uint32_t tri, double t_max) const {
  const glm::dvec3& p0 = positions_[indices_[3 * tri]];
  const glm::dvec3& p1 = positions_[indices_[3 * tri + 1]];
  const glm::dvec3& p2 = positions_[indices_[3 * tri + 2]];
  const auto th = intersect_triangle(ray, p0, p1, p2, t_max);
  if (!th) return std::nullopt;
  const glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
  const double len = glm::length(n);
  if (!(len > 0.0)) return std::nullopt;  // degenerate: no normal to spawn along
  ShapeHit hit;
  hit.t = th->t;
  hit.p = th->b0 * p0 + th->b1 * p1 + th->b2 * p2;
  hit.p_error = rounding_gamma(7) * (glm::abs(th->b0 * p0) + glm::abs(th->b1 * p1) + glm::abs(th->b2 * p2));
  hit.n = n / len;
  hit.uv = {th->b1, th->b2};
  hit.primitive = tri;
  return hit;
}

std::optional<ShapeHit> TriangleMesh::intersect(const Ray& ray, double t_max) const {
  std::optional<ShapeHit> best;
  const auto n = static_cast<std::uint32_t>(triangle_count());
  for (std::uint32_t tri = 0; tri < n; ++tri) {
    if (auto h = intersect(ray, tri, t_max)) {
      t_max = h->t;
      best = h;
    }
  }
  return best;
}

glm::dvec3 TriangleMesh::geometric_normal(std::uint32_t tri) const {
  const glm::dvec3& p0 = positions_[indices_[3 * tri]];
  return glm::normalize(glm::cross(positions_[indices_[3 * tri + 1]] - p0, positions_[indices_[3 * tri + 2]] - p0));
}

glm::dvec3 TriangleMesh::shading_normal(std::uint32_t tri, double b1, double b2) const {
  if (normals_.empty()) return geometric_normal(tri);
  const glm::dvec3 n = (1.0 - b1 - b2) * normals_[indices_[3 * tri]] + b1 * normals_[indices_[3 * tri + 1]] +
                       b2 * normals_[indices_[3 * tri + 2]];
  const double len = glm::length(n);
  return len > 0.0 ? n / len : geometric_normal(tri);
}

double TriangleMesh::area(std::uint32_t tri) const {
  const glm::dvec3& p0 = positions_[indices_[3 * tri]];
  return 0.5 * glm::length(glm::cross(positions_[indices_[3 * tri + 1]] - p0, positions_[indices_[3 * tri + 2]] - p0));
}

}  // namespace skyfarm
