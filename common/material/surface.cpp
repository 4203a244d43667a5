#include "common/material/surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/material/direction_sampling.h"

namespace skyfarm::material {
namespace {

std::shared_ptr<const Material> resolve(const SurfaceSpec& spec) {
  if (!spec.custom) {
    // Named materials live for the whole program: a non-owning pointer.
    return std::shared_ptr<const Material>(std::shared_ptr<const Material>(), &named_material(spec.name));
  }
  if (spec.kind == MaterialKind::kDiffuse)
    return std::make_shared<const Material>(custom_albedo_material(spec.name, spec.wavelengths_nm, spec.albedo));
  const std::vector<double> k = spec.k.empty() ? std::vector<double>(spec.wavelengths_nm.size(), 0.0) : spec.k;
  return std::make_shared<const Material>(custom_ior_material(spec.name, spec.kind, spec.wavelengths_nm, spec.n, k));
}

bool roughness_ok(double alpha) { return alpha == 0.0 || (alpha >= kMinRoughness && alpha <= kMaxRoughness); }

// Gauss-Legendre nodes and weights on [-1, 1], 16 points (Abramowitz & Stegun
// table 25.4); the positive half, the rest by symmetry.
constexpr std::array<double, 8> kGaussX = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274,
                                           0.6178762444026438, 0.7554044083550030, 0.8656312023878318,
                                           0.9445750230732326, 0.9894009349916499};
constexpr std::array<double, 8> kGaussW = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025,
                                           0.1495959888165767, 0.1246289712555339, 0.0951585116824928,
                                           0.0622535239386479, 0.0271524594117541};
constexpr int kAlbedoSamplesPerNode = 64;

}  // namespace

Surface::Surface(SurfaceSpec spec) : spec_(std::move(spec)), material_(resolve(spec_)) {
  if (!roughness_ok(spec_.roughness_x) || !roughness_ok(spec_.roughness_y) ||
      ((spec_.roughness_x == 0.0) != (spec_.roughness_y == 0.0)))
    throw std::invalid_argument("roughness must be 0 (smooth) or in [" + std::to_string(kMinRoughness) + ", " +
                                std::to_string(kMaxRoughness) + "] along both axes");
}

SurfaceBsdf Surface::bsdf(double lambda_nm, Body body) const {
  // A smooth surface has no distribution (alpha 0 is its delta limit).
  const MicrofacetDistribution d(spec_.distribution, spec_.smooth() ? 1.0 : spec_.roughness_x,
                                 spec_.smooth() ? 1.0 : spec_.roughness_y);
  switch (kind()) {
    case MaterialKind::kConductor: {
      const ConductorFresnel fresnel{material_->ior().at(lambda_nm).eta(), false};
      if (spec_.smooth()) return SurfaceBsdf(SmoothReflector(fresnel));
      if (spec_.multiple_bounce) return SurfaceBsdf(MultipleBounceBsdf(d, Facet::conductor(fresnel)));
      return SurfaceBsdf(RoughConductor(d, fresnel));
    }
    case MaterialKind::kDielectric: {
      const double eta = material_->ior().n(lambda_nm);
      if (transmits(body)) {
        // Without the (n_wo / n_wi)^2 radiance factor, as the rough forms
        // evaluated the way the path tracer does (surface.h).
        if (spec_.smooth()) return SurfaceBsdf(SmoothDielectric(eta, TransportMode::importance));
        if (spec_.multiple_bounce) return SurfaceBsdf(MultipleBounceBsdf(d, Facet::dielectric(eta)));
        return SurfaceBsdf(RoughDielectric(d, eta));
      }
      // Over an opaque body: only the reflected directions are proposed.
      if (spec_.smooth()) return SurfaceBsdf(SmoothReflector::dielectric(eta));
      if (spec_.multiple_bounce)
        return SurfaceBsdf::reflection_only(MultipleBounceBsdf(d, Facet::dielectric(eta)), d, 0.25);
      return SurfaceBsdf::reflection_only(RoughDielectric(d, eta), d, 0.0);
    }
    case MaterialKind::kDiffuse: {
      const double albedo = std::clamp(material_->albedo().at(lambda_nm), 0.0, 1.0);
      if (spec_.smooth()) return SurfaceBsdf(Lambertian(albedo));
      if (spec_.multiple_bounce) return SurfaceBsdf(MultipleBounceBsdf(d, Facet::diffuse(albedo)));
      return SurfaceBsdf(RoughDiffuse(d, albedo));
    }
  }
  return {};
}

std::string Surface::model_name() const {
  if (lambertian()) return "lambertian";
  const std::string kind_name = kind() == MaterialKind::kConductor    ? "conductor"
                                : kind() == MaterialKind::kDielectric ? "dielectric"
                                                                      : "diffuse";
  if (spec_.smooth()) return "smooth_" + kind_name;
  return (spec_.multiple_bounce ? "multiple_bounce_" : "rough_") + kind_name;
}

// A = integral_0^1 A(mu) 2 mu dmu, A(mu) the mean of sample()'s value over
// the reflected directions (what goes below the surface is absorbed).
double Surface::white_sky_albedo(double lambda_nm) const {
  if (lambertian()) return std::clamp(material_->albedo().at(lambda_nm), 0.0, 1.0);
  const SurfaceBsdf surface_bsdf = bsdf(lambda_nm);
  const Bsdf& b = surface_bsdf.get();
  double total = 0.0;
  for (int node = 0; node < 16; ++node) {
    const int half = node < 8 ? node : node - 8;
    const double x = node < 8 ? -kGaussX[half] : kGaussX[half];
    const double mu = 0.5 * (x + 1.0);
    const double weight = 0.5 * kGaussW[half];
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    double sum = 0.0;
    // The same seed at every wavelength: the table's noise is smooth in lambda.
    RandomSequence rng(0x5EEDu + static_cast<std::uint64_t>(node));
    const int n = surface_bsdf.specular() ? 1 : kAlbedoSamplesPerNode;
    for (int s = 0; s < n; ++s) {
      const double phi = 2.0 * kBsdfPi * rng.next();  // every azimuth: anisotropic surfaces
      const glm::dvec3 wo(sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu);
      const double uc = rng.next(), u0 = rng.next(), u1 = rng.next();
      if (surface_bsdf.specular()) {
        const std::optional<BsdfSample> sample = b.sample(wo, uc, {u0, u1}, rng);
        if (sample && std::isfinite(sample->value)) sum += sample->value;
        continue;
      }
      // The proposal the path tracer uses, f with the walk from the viewer's side.
      const std::optional<glm::dvec3> wi = surface_bsdf.propose(wo, uc, {u0, u1});
      if (!wi || !(wi->z > 0.0)) continue;
      const double value = b.f(*wi, wo, rng) * wi->z / surface_bsdf.pdf(wo, *wi);
      if (std::isfinite(value)) sum += value;
    }
    total += weight * 2.0 * mu * (sum / n);
  }
  return std::clamp(total, 0.0, 1.0);
}

SpectralTable Surface::white_sky_albedo_table(double lo_nm, double hi_nm, double step_nm) const {
  SpectralTable t;
  const int steps = static_cast<int>(std::ceil((hi_nm - lo_nm) / step_nm - 1e-9));
  for (int i = 0; i <= steps; ++i) {
    const double lambda = std::min(hi_nm, lo_nm + i * step_nm);
    t.wavelengths_nm.push_back(lambda);
    t.values.push_back(white_sky_albedo(lambda));
  }
  return t;
}

}  // namespace skyfarm::material
