// A perfectly smooth surface seen from above: the specular limit (alpha -> 0)
// of a conductor, or the reflection of a dielectric interface whose
// transmitted light is absorbed below it (deep water, an opaque body behind
// the glass).  A delta lobe: f and pdf are 0 as functions; sample() returns
// the mirror direction with value F(cos theta), pdf 1 and kBsdfSpecular, so a
// path tracer follows it and never combines it with light sampling.
//
// Parameters
//   fresnel   ConductorFresnel (complex index) or, with dielectric(eta), the
//             exact unpolarised dielectric reflectance for eta = n_below /
//             n_above.
#pragma once

#include "common/material/bsdf.h"
#include "common/material/conductor_fresnel.h"

namespace skyfarm::material {

class SmoothReflector final : public Bsdf {
 public:
  explicit SmoothReflector(ConductorFresnel fresnel) : fresnel_(fresnel) {}
  static SmoothReflector dielectric(double eta);

  std::uint32_t flags() const override { return kBsdfReflection | kBsdfSpecular; }
  bool stochastic() const override { return false; }
  double f(const glm::dvec3&, const glm::dvec3&, RandomSequence&) const override { return 0.0; }
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                   RandomSequence& rng) const override;
  double pdf(const glm::dvec3&, const glm::dvec3&) const override { return 0.0; }

  // F at the angle of incidence whose cosine is cos_theta (> 0).
  double reflectance(double cos_theta) const;

 private:
  SmoothReflector(ConductorFresnel fresnel, double eta, bool is_dielectric)
      : fresnel_(fresnel), eta_(eta), is_dielectric_(is_dielectric) {}
  ConductorFresnel fresnel_;
  double eta_ = 1.0;
  bool is_dielectric_ = false;
};

}  // namespace skyfarm::material
