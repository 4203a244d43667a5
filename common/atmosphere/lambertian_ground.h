// The ground: a Lambertian reflector with a scalar or spectral albedo
// rho(lambda), BRDF f = rho / pi, sampled proportionally to cos(theta).
#pragma once
#include <glm/vec3.hpp>

#include "common/core/piecewise_linear.h"

namespace skyfarm {

class LambertianGround {
 public:
  LambertianGround() : albedo_(PiecewiseLinear::constant(0.3)) {}
  explicit LambertianGround(PiecewiseLinear albedo) : albedo_(std::move(albedo)) {}

  // rho(lambda), held at the end values outside the table.
  double albedo(double lambda_nm) const { return albedo_(lambda_nm); }
  // f(wo, wi) = rho / pi for wi above the surface, 0 below.
  double brdf(double lambda_nm, double cos_theta_i) const;
  // A direction about the normal n with pdf cos(theta) / pi.
  glm::dvec3 sample_direction(const glm::dvec3& n, double u1, double u2, double* pdf) const;
  const PiecewiseLinear& albedo_table() const { return albedo_; }

 private:
  PiecewiseLinear albedo_;
};

}  // namespace skyfarm
