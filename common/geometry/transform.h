// An affine transform in double precision, x' = A x + b (a 4x4 matrix with
// last row 0 0 0 1), with its inverse kept alongside.
//
//   points      A p + b
//   directions  A d (not renormalised: a ray carried to another frame keeps
//               its parameter t, so hits compare across frames)
//   normals     A^-T n (the inverse transpose keeps them perpendicular to
//               the surface under non-uniform scale; normal() renormalises)
//   errors      point_error() bounds the rounding of A p + b given a bound on
//               p's (PBR 3rd ed., §3.9.3): gamma(3)(|A||p| + |b|) + (1 + gamma(3))|A| e
//
// to_parent(hit) carries a ShapeHit from the object's frame to the parent's
// (the local ENU frame for a placed object): t unchanged, p transformed, the
// normal by the inverse transpose, and p_error grown by the forward rounding
// and by the rounding the point will see on its way back into the object's
// frame (when a spawned ray is intersected again), so spawn.h's offset
// clears both.
#pragma once
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "common/geometry/ray.h"
#include "common/geometry/shape_hit.h"

namespace skyfarm {

class Transform {
 public:
  Transform();  // identity
  // Throws std::invalid_argument when the last row is not 0 0 0 1, or A is
  // singular or not finite.
  explicit Transform(const glm::dmat4& m);

  const glm::dmat4& matrix() const { return m_; }
  const glm::dmat4& inverse_matrix() const { return inv_; }
  Transform inverse() const;
  Transform operator*(const Transform& rhs) const;  // rhs first, then this

  glm::dvec3 point(const glm::dvec3& p) const;
  glm::dvec3 direction(const glm::dvec3& d) const;
  glm::dvec3 normal(const glm::dvec3& n) const;  // unit
  glm::dvec3 point_error(const glm::dvec3& p, const glm::dvec3& p_error) const;
  Ray ray(const Ray& r) const;

  ShapeHit to_parent(const ShapeHit& object_hit) const;
  // The factor by which the transform scales area at a point whose object
  // normal is n: |det A| |A^-T n| (for unit n).  An area pdf in the object's
  // frame divided by it is the pdf per unit parent area.
  double area_scale(const glm::dvec3& object_normal) const;
  AreaSample to_parent(const AreaSample& object_sample) const;

 private:
  Transform(const glm::dmat4& m, const glm::dmat4& inv) : m_(m), inv_(inv) {}
  glm::dmat4 m_, inv_;
};

}  // namespace skyfarm
