// Every BSDF's sample() against its pdf(): the directions it proposes follow
// pdf (a chi-square test over bins of the sphere, expected counts by
// quadrature of pdf), the returned pdf is pdf(wo, wi), and the returned
// value is f |wi.z| / pdf (exactly for the deterministic forms).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/material/lambertian.h"
#include "common/material/multiple_bounce_bsdf.h"
#include "common/material/rough_conductor.h"
#include "common/material/rough_dielectric.h"
#include "common/material/rough_diffuse.h"
#include "tests/common/material/sphere_quadrature.h"

namespace skyfarm::material {
namespace {

using test::kPi;

constexpr int kZBins = 20;    // cos(theta) in [-1, 1]
constexpr int kPhiBins = 24;  // phi in [0, 2 pi)

glm::dvec3 from_z_phi(double z, double phi) {
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

int bin_of(const glm::dvec3& w) {
  const int iz = std::clamp(static_cast<int>((w.z + 1.0) / 2.0 * kZBins), 0, kZBins - 1);
  double phi = std::atan2(w.y, w.x);
  if (phi < 0.0) phi += 2.0 * kPi;
  const int ip = std::clamp(static_cast<int>(phi / (2.0 * kPi) * kPhiBins), 0, kPhiBins - 1);
  return iz * kPhiBins + ip;
}

// Expected probability of each bin: pdf integrated by an 8 x 8 Gauss-Legendre
// rule in (cos(theta), phi), where solid angle is dz dphi.
std::vector<double> bin_probabilities(const Bsdf& bsdf, const glm::dvec3& wo) {
  static const test::GaussLegendre gl = test::gauss_legendre(8);
  std::vector<double> p(kZBins * kPhiBins, 0.0);
  const double dz = 2.0 / kZBins;
  const double dphi = 2.0 * kPi / kPhiBins;
  for (int iz = 0; iz < kZBins; ++iz) {
    for (int ip = 0; ip < kPhiBins; ++ip) {
      double sum = 0.0;
      for (std::size_t a = 0; a < gl.x.size(); ++a) {
        for (std::size_t b = 0; b < gl.x.size(); ++b) {
          const double z = -1.0 + dz * (iz + 0.5 + 0.5 * gl.x[a]);
          const double phi = dphi * (ip + 0.5 + 0.5 * gl.x[b]);
          sum += 0.25 * gl.w[a] * gl.w[b] * bsdf.pdf(wo, from_z_phi(z, phi));
        }
      }
      p[iz * kPhiBins + ip] = sum * dz * dphi;
    }
  }
  return p;
}

void check_sampling(const std::string& name, const Bsdf& bsdf, const glm::dvec3& wo, int samples) {
  SCOPED_TRACE(name);
  const std::vector<double> expected = bin_probabilities(bsdf, wo);
  std::vector<double> observed(expected.size(), 0.0);
  RandomSequence rng(9001);
  RandomSequence eval_rng(1);
  int returned = 0;
  for (int i = 0; i < samples; ++i) {
    const double uc = rng.next();
    const double u0 = rng.next();
    const double u1 = rng.next();
    const auto s = bsdf.sample(wo, uc, {u0, u1}, rng);
    if (!s) continue;
    ++returned;
    observed[bin_of(s->wi)] += 1.0;
    ASSERT_TRUE(std::isfinite(s->value) && s->value >= 0.0);
    const double pdf = bsdf.pdf(wo, s->wi);
    ASSERT_NEAR(s->pdf, pdf, 1e-9 * pdf);
    if (!bsdf.stochastic()) {
      const double weight = bsdf.f(wo, s->wi, eval_rng) * std::abs(s->wi.z) / pdf;
      ASSERT_NEAR(s->value, weight, 1e-9 * weight + 1e-300);
    }
  }
  // Chi-square over the bins with an expected count >= 5, the rest pooled
  // with the proposals that returned nothing (pdf's missing mass).
  double chi = 0.0;
  int cells = 0;
  double pooled_expected = samples;
  double pooled_observed = samples;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const double e = expected[k] * samples;
    if (e < 5.0) continue;
    chi += (observed[k] - e) * (observed[k] - e) / e;
    pooled_expected -= e;
    pooled_observed -= observed[k];
    ++cells;
  }
  if (pooled_expected >= 5.0) {
    chi += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) / pooled_expected;
    ++cells;
  } else {
    EXPECT_LT(pooled_observed, 5.0 + 6.0 * std::sqrt(5.0));
  }
  const int dof = cells - 1;
  // Wilson-Hilferty: chi^2(dof) exceeds dof (1 - 2/(9 dof) + z sqrt(2/(9 dof)))^3
  // with probability ~1e-7 for z = 5.2.
  const double c = 2.0 / (9.0 * dof);
  const double threshold = dof * std::pow(1.0 - c + 5.2 * std::sqrt(c), 3.0);
  std::printf("%s: chi2 %.1f / %d dof (threshold %.1f), %d of %d proposals returned\n", name.c_str(), chi, dof,
              threshold, returned, samples);
  EXPECT_LT(chi, threshold);
  EXPECT_GT(cells, 20);
}

glm::dvec3 direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

TEST(BsdfSampling, Lambertian) { check_sampling("lambertian", Lambertian(0.8), direction(0.5, 0.3), 100000); }

TEST(BsdfSampling, RoughConductor) {
  const ConductorFresnel gold{{0.43, 2.46}, false};
  check_sampling("conductor ggx 0.5x0.3",
                 RoughConductor(MicrofacetDistribution(MicrofacetModel::ggx, 0.5, 0.3), gold), direction(0.6, 0.4),
                 100000);
  check_sampling("conductor beckmann 0.4 grazing",
                 RoughConductor(MicrofacetDistribution(MicrofacetModel::beckmann, 0.4, 0.4), gold),
                 direction(1.3, 1.0), 100000);
}

TEST(BsdfSampling, RoughDielectric) {
  const RoughDielectric glass(MicrofacetDistribution(MicrofacetModel::ggx, 0.4, 0.4), 1.5);
  check_sampling("dielectric from outside", glass, direction(0.6, 0.2), 100000);
  check_sampling("dielectric from inside", glass, direction(kPi - 0.4, 0.2), 100000);
  check_sampling("dielectric from inside past the critical angle", glass, direction(kPi - 1.2, 0.2), 100000);
}

TEST(BsdfSampling, RoughDiffuse) {
  check_sampling("rough diffuse", RoughDiffuse(MicrofacetDistribution(MicrofacetModel::ggx, 0.5, 0.5), 0.8),
                 direction(0.7, 0.0), 100000);
}

TEST(BsdfSampling, MultipleBounce) {
  const MicrofacetDistribution dist(MicrofacetModel::ggx, 0.5, 0.5);
  check_sampling("multiple-bounce conductor",
                 MultipleBounceBsdf(dist, Facet::conductor(ConductorFresnel{{0.2, 3.0}, false})),
                 direction(0.6, 0.1), 50000);
  check_sampling("multiple-bounce diffuse", MultipleBounceBsdf(dist, Facet::diffuse(0.8)), direction(0.6, 0.1),
                 50000);
  check_sampling("multiple-bounce dielectric", MultipleBounceBsdf(dist, Facet::dielectric(1.5)),
                 direction(0.6, 0.1), 50000);
  check_sampling("multiple-bounce dielectric from inside", MultipleBounceBsdf(dist, Facet::dielectric(1.5)),
                 direction(kPi - 0.6, 0.1), 50000);
}

}  // namespace
}  // namespace skyfarm::material
