#include "common/geometry/transform.h"

#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <stdexcept>

#include "common/geometry/rounding_error.h"

namespace skyfarm {
namespace {

// glm is column-major: m[column][row].
glm::dvec3 abs_linear(const glm::dmat4& m, const glm::dvec3& v) {
  glm::dvec3 r(0.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i] += std::abs(m[j][i]) * v[j];
  return r;
}

glm::dvec3 abs_translation(const glm::dmat4& m) { return {std::abs(m[3][0]), std::abs(m[3][1]), std::abs(m[3][2])}; }

glm::dvec3 rounding_of_point(const glm::dmat4& m, const glm::dvec3& p) {
  return rounding_gamma(3) * (abs_linear(m, glm::abs(p)) + abs_translation(m));
}

}  // namespace

Transform::Transform() : m_(1.0), inv_(1.0) {}

Transform::Transform(const glm::dmat4& m) : m_(m) {
  if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
    throw std::invalid_argument("transform: not affine (last row must be 0 0 0 1)");
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r)
      if (!std::isfinite(m[c][r])) throw std::invalid_argument("transform: not finite");
  const glm::dmat3 a(m);
  const double det = glm::determinant(a);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) throw std::invalid_argument("transform: singular");
  const glm::dmat3 a_inv = glm::inverse(a);
  const glm::dvec3 b(m[3]);
  inv_ = glm::dmat4(a_inv);
  inv_[3] = glm::dvec4(-(a_inv * b), 1.0);
}

Transform Transform::inverse() const { return Transform(inv_, m_); }

Transform Transform::operator*(const Transform& rhs) const { return Transform(m_ * rhs.m_, rhs.inv_ * inv_); }

glm::dvec3 Transform::point(const glm::dvec3& p) const { return glm::dvec3(m_ * glm::dvec4(p, 1.0)); }

glm::dvec3 Transform::direction(const glm::dvec3& d) const { return glm::dmat3(m_) * d; }

glm::dvec3 Transform::normal(const glm::dvec3& n) const {
  return glm::normalize(glm::transpose(glm::dmat3(inv_)) * n);
}

glm::dvec3 Transform::point_error(const glm::dvec3& p, const glm::dvec3& p_error) const {
  return rounding_of_point(m_, p) + (1.0 + rounding_gamma(3)) * abs_linear(m_, p_error);
}

Ray Transform::ray(const Ray& r) const { return {point(r.o), direction(r.d)}; }

ShapeHit Transform::to_parent(const ShapeHit& h) const {
  ShapeHit out = h;
  out.p = point(h.p);
  out.n = normal(h.n);
  // Forward rounding, then the return trip: the spawned origin is carried
  // back by the inverse with error gamma(3)(|A^-1||p'| + |b'|) in the
  // object's frame, which A maps back to the parent's.
  const glm::dvec3 back = rounding_of_point(inv_, out.p);
  out.p_error = point_error(h.p, h.p_error) + (1.0 + rounding_gamma(3)) * abs_linear(m_, back);
  return out;
}

double Transform::area_scale(const glm::dvec3& n) const {
  const glm::dmat3 a(m_);
  return std::abs(glm::determinant(a)) * glm::length(glm::transpose(glm::dmat3(inv_)) * n);
}

AreaSample Transform::to_parent(const AreaSample& s) const {
  return {point(s.p), normal(s.n), s.pdf_area / area_scale(s.n)};
}

}  // namespace skyfarm
