// One surface's BSDF at one wavelength, held by value: the path tracer
// builds one per wavelength of a path at every surface vertex (a few doubles
// each, no allocation) and calls them through the Bsdf interface.
#pragma once

#include <optional>
#include <variant>

#include "common/material/bsdf.h"
#include "common/material/lambertian.h"
#include "common/material/multiple_bounce_bsdf.h"
#include "common/material/rough_conductor.h"
#include "common/material/rough_dielectric.h"
#include "common/material/rough_diffuse.h"
#include "common/material/smooth_reflector.h"

namespace skyfarm::material {

class SurfaceBsdf {
 public:
  SurfaceBsdf() = default;
  template <class B>
  explicit SurfaceBsdf(B bsdf) : bsdf_(std::move(bsdf)) {}

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
  bool specular() const { return std::holds_alternative<SmoothReflector>(bsdf_); }

  // A direction drawn from sample()'s proposal (density pdf(wo, .)) without
  // evaluating f: the path tracer proposes with the hero wavelength's BSDF
  // and evaluates f and pdf at every wavelength.  nullopt when the proposal
  // fails.
  std::optional<glm::dvec3> propose(const glm::dvec3& wo, double uc, const glm::dvec2& u) const {
    if (const auto* m = std::get_if<MultipleBounceBsdf>(&bsdf_)) return m->propose(wo, uc, u);
    RandomSequence unused(0);  // the exact forms draw nothing; rough diffuse's draws only feed its f
    const std::optional<BsdfSample> s = get().sample(wo, uc, u, unused);
    if (!s) return std::nullopt;
    return s->wi;
  }

 private:
  std::variant<std::monostate, Lambertian, RoughConductor, RoughDielectric, RoughDiffuse, MultipleBounceBsdf,
               SmoothReflector>
      bsdf_;
};

}  // namespace skyfarm::material
