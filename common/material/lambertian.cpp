#include "common/material/lambertian.h"

#include <stdexcept>

#include "common/material/direction_sampling.h"

namespace skyfarm::material {

Lambertian::Lambertian(double albedo) : albedo_(albedo) {
  if (!(albedo >= 0.0 && albedo <= 1.0)) throw std::invalid_argument("Lambertian: albedo outside [0, 1]");
}

double Lambertian::f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence&) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  return albedo_ / kBsdfPi;
}

std::optional<BsdfSample> Lambertian::sample(const glm::dvec3& wo, double, const glm::dvec2& u,
                                             RandomSequence&) const {
  if (wo.z <= 0.0) return std::nullopt;
  const glm::dvec3 wi = sample_cosine_around({0.0, 0.0, 1.0}, u);
  if (wi.z <= 0.0) return std::nullopt;
  return BsdfSample{wi, albedo_, wi.z / kBsdfPi, kBsdfReflection | kBsdfDiffuse};
}

double Lambertian::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  return wi.z / kBsdfPi;
}

}  // namespace skyfarm::material
