// One surface's BSDF at one wavelength, held by value: the path tracer
// builds one per wavelength of a path at every surface vertex (a few doubles
// each, no allocation) and calls them through the Bsdf interface.
//
// A surface over an opaque body (the ground: what a dielectric transmits is
// absorbed in the deep water below) needs only the reflected directions.
// reflection_only() replaces the BSDF's own proposal, which for water sends
// ~95 % of its samples into the water, by one over the upper hemisphere: the
// mirror of wo about a visible normal (Heitz 2018), mixed with a cosine-
// weighted hemisphere with probability cosine_share.  propose() and pdf()
// below are then that proposal and its density; f is the BSDF's.
#pragma once

#include <optional>
#include <variant>

#include "common/material/bsdf.h"
#include "common/material/lambertian.h"
#include "common/material/multiple_bounce_bsdf.h"
#include "common/material/rough_conductor.h"
#include "common/material/rough_dielectric.h"
#include "common/material/rough_diffuse.h"
#include "common/material/smooth_dielectric.h"
#include "common/material/smooth_reflector.h"

namespace skyfarm::material {

class SurfaceBsdf {
 public:
  SurfaceBsdf() = default;
  template <class B>
  explicit SurfaceBsdf(B bsdf) : bsdf_(std::move(bsdf)) {}

  // The BSDF with the reflection-only proposal (see the top of this file).
  template <class B>
  static SurfaceBsdf reflection_only(B bsdf, const MicrofacetDistribution& distribution, double cosine_share) {
    SurfaceBsdf s(std::move(bsdf));
    s.reflection_ = Reflection{distribution, cosine_share};
    return s;
  }

  bool empty() const { return std::holds_alternative<std::monostate>(bsdf_); }
  // Precondition: !empty().
  const Bsdf& get() const {
    return *std::visit(
        [](const auto& b) -> const Bsdf* {
          if constexpr (std::is_same_v<std::decay_t<decltype(b)>, std::monostate>) return nullptr;
          else return &b;
        },
        bsdf_);
  }
  // A delta lobe (SmoothReflector, SmoothDielectric): f and pdf are not functions.
  bool specular() const {
    return std::holds_alternative<SmoothReflector>(bsdf_) || std::holds_alternative<SmoothDielectric>(bsdf_);
  }
  // The smooth interface light crosses, or null.
  const SmoothDielectric* smooth_dielectric() const { return std::get_if<SmoothDielectric>(&bsdf_); }

  // A direction drawn from the proposal (density pdf(wo, .)) without
  // evaluating f: the path tracer proposes with the hero wavelength's BSDF
  // and evaluates f and pdf at every wavelength.  nullopt when the proposal
  // fails.
  std::optional<glm::dvec3> propose(const glm::dvec3& wo, double uc, const glm::dvec2& u) const;
  // The proposal's density over solid angle (deterministic).
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const;

 private:
  struct Reflection {
    MicrofacetDistribution distribution;
    double cosine_share = 0.0;
  };
  std::variant<std::monostate, Lambertian, RoughConductor, RoughDielectric, RoughDiffuse, MultipleBounceBsdf,
               SmoothReflector, SmoothDielectric>
      bsdf_;
  std::optional<Reflection> reflection_;
};

}  // namespace skyfarm::material
