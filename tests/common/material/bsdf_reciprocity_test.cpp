// Reciprocity of reflection, f(wo, wi) = f(wi, wo): exactly for the
// deterministic BSDFs, in expectation (means of independent estimates within
// their noise) for the stochastic ones.  The height-correlated
// multiple-bounce model is not reciprocal (Wang et al. 2022, supplement
// §2.2) and is left out; the height-uncorrelated one is (§2.1).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>

#include "common/material/lambertian.h"
#include "common/material/multiple_bounce_bsdf.h"
#include "common/material/rough_conductor.h"
#include "common/material/rough_dielectric.h"
#include "common/material/rough_diffuse.h"

namespace skyfarm::material {
namespace {

glm::dvec3 direction(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

struct Pair {
  glm::dvec3 a;
  glm::dvec3 b;
};

const Pair kPairs[] = {
    {direction(0.3, 0.0), direction(0.9, 2.0)},
    {direction(1.2, 0.5), direction(0.1, 4.0)},
    {direction(1.45, 1.0), direction(1.3, 3.5)},
    {direction(0.7, 0.2), direction(0.7, 3.3)},
};

TEST(BsdfReciprocity, DeterministicReflectionIsExactlyReciprocal) {
  const MicrofacetDistribution aniso(MicrofacetModel::ggx, 0.6, 0.15);
  const Lambertian lambert(0.7);
  const RoughConductor conductor(aniso, ConductorFresnel{{0.43, 2.46}, false});
  const RoughDielectric dielectric(MicrofacetDistribution(MicrofacetModel::beckmann, 0.3, 0.3), 1.5);
  RandomSequence rng(1);
  for (const Bsdf* bsdf : {static_cast<const Bsdf*>(&lambert), static_cast<const Bsdf*>(&conductor),
                           static_cast<const Bsdf*>(&dielectric)}) {
    for (const Pair& p : kPairs) {
      const double ab = bsdf->f(p.a, p.b, rng);
      const double ba = bsdf->f(p.b, p.a, rng);
      EXPECT_GT(ab, 0.0);
      EXPECT_NEAR(ab, ba, 1e-12 * ab);
    }
  }
}

// Means of n estimates each way; they agree within 4.5 standard errors of
// the difference.
void expect_reciprocal_in_expectation(const char* name, const Bsdf& bsdf, int n) {
  RandomSequence rng(77);
  for (const Pair& p : kPairs) {
    double s[2] = {0.0, 0.0};
    double s2[2] = {0.0, 0.0};
    for (int i = 0; i < n; ++i) {
      const double ab = bsdf.f(p.a, p.b, rng);
      const double ba = bsdf.f(p.b, p.a, rng);
      s[0] += ab;
      s2[0] += ab * ab;
      s[1] += ba;
      s2[1] += ba * ba;
    }
    const double m0 = s[0] / n;
    const double m1 = s[1] / n;
    const double var = (s2[0] / n - m0 * m0 + s2[1] / n - m1 * m1) / n;
    std::printf("%s: f(a, b) %.5f, f(b, a) %.5f, z %.2f\n", name, m0, m1, (m0 - m1) / std::sqrt(var));
    EXPECT_GT(m0, 0.0);
    EXPECT_NEAR(m0, m1, 4.5 * std::sqrt(var)) << name;
  }
}

TEST(BsdfReciprocity, RoughDiffuseIsReciprocalInExpectation) {
  expect_reciprocal_in_expectation("rough diffuse 0.5",
                                   RoughDiffuse(MicrofacetDistribution(MicrofacetModel::ggx, 0.5, 0.5), 0.9), 200000);
}

TEST(BsdfReciprocity, UncorrelatedMultipleBounceIsReciprocalInExpectation) {
  const MicrofacetDistribution iso(MicrofacetModel::ggx, 0.8, 0.8);
  const MicrofacetDistribution aniso(MicrofacetModel::ggx, 1.0, 0.3);
  expect_reciprocal_in_expectation(
      "multiple-bounce conductor 0.8",
      MultipleBounceBsdf(iso, Facet::conductor(ConductorFresnel{{0.2, 3.0}, false}), HeightCorrelation::uncorrelated),
      100000);
  expect_reciprocal_in_expectation(
      "multiple-bounce diffuse 1.0 x 0.3",
      MultipleBounceBsdf(aniso, Facet::diffuse(0.9), HeightCorrelation::uncorrelated), 100000);
}

}  // namespace
}  // namespace skyfarm::material
