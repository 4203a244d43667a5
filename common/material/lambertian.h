// Lambertian reflection: f = albedo / pi on the upper hemisphere.
//
// Parameters
//   albedo  the directional-hemispherical reflectance at this wavelength, in
//           [0, 1] (the constructor throws std::invalid_argument outside).
//
// Reflection only: f, pdf and sample() are 0 / nullopt when wo or wi is
// below the macro surface.  Sampling is cosine-weighted, so the sample value
// is the albedo.
#pragma once

#include "common/material/bsdf.h"

namespace skyfarm::material {

class Lambertian final : public Bsdf {
 public:
  explicit Lambertian(double albedo);

  std::uint32_t flags() const override { return kBsdfReflection | kBsdfDiffuse; }
  bool stochastic() const override { return false; }
  double f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const override;
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                   RandomSequence& rng) const override;
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const override;

 private:
  double albedo_;
};

}  // namespace skyfarm::material
