// A perfectly smooth dielectric interface that light crosses: the specular
// limit (alpha -> 0) of RoughDielectric.  Two delta lobes: the mirror
// direction, with the Fresnel reflectance F, and the refracted direction
// (Snell's law), with 1 - F; under total internal reflection F = 1.  f and
// pdf are 0 as functions; sample() picks a lobe with probability F (reflect)
// or 1 - F (refract), so its value is 1 for a reflection and the radiance
// factor for a refraction, and pdf is that discrete probability, flagged
// kBsdfSpecular.
//
// Parameters
//   eta        n_inside / n_outside > 0, != 1 (glass in air 1.5).  The inside
//              is below the macro surface (z < 0); wo may be on either side
//              (a wo below sees the interface from the inside: the relative
//              index inverts, as for RoughDielectric).
//   transport  TransportMode::radiance (camera paths): a refracted sample
//              carries (n_wo / n_wi)^2, radiance being compressed by the
//              square of the index it enters (Veach 1997, §5.2); ::importance:
//              no factor (the transmitted flux fraction 1 - F).  Along a path
//              that enters and leaves a body the two factors cancel.
#pragma once

#include "common/material/bsdf.h"
#include "common/material/rough_dielectric.h"

namespace skyfarm::material {

class SmoothDielectric final : public Bsdf {
 public:
  explicit SmoothDielectric(double eta, TransportMode transport = TransportMode::radiance);

  std::uint32_t flags() const override { return kBsdfReflection | kBsdfTransmission | kBsdfSpecular; }
  bool stochastic() const override { return false; }
  double f(const glm::dvec3&, const glm::dvec3&, RandomSequence&) const override { return 0.0; }
  std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                   RandomSequence& rng) const override;
  double pdf(const glm::dvec3&, const glm::dvec3&) const override { return 0.0; }

  double eta() const { return eta_; }

  // One of the two lobes seen from wo: its direction, its weight (F, or
  // (1 - F) times the radiance factor) and the probability sample() picks
  // it with (F or 1 - F).  The path tracer picks the lobe with the hero
  // wavelength and weighs the others' with these.  nullopt when the lobe
  // does not exist (refraction under total internal reflection, wo.z 0).
  struct Lobe {
    glm::dvec3 wi{0.0, 0.0, 1.0};
    double weight = 0.0;
    double probability = 0.0;
  };
  std::optional<Lobe> lobe(const glm::dvec3& wo, bool reflect) const;

 private:
  double eta_;
  TransportMode transport_;
};

}  // namespace skyfarm::material
